//! What the surfaces of revolution about z (spheres, disks, cylinders) share: the sweep in
//! azimuth and its clipping, the u tangent of u = phi / phi_max, and the roots of the quadratic
//! their intersections solve.

use std::f32::consts::TAU;

use glam::Vec3A;

use crate::math::atan2;

/// Radius of spheres, disks and cylinders when the file does not say.
pub const DEFAULT_RADIUS: f32 = 1.0;
/// Sweep of spheres, disks and cylinders in degrees when the file does not say.
pub const DEFAULT_PHIMAX: f32 = 360.0;

/// A sweep the scene gives in degrees, in radians within [0, TAU].
pub(crate) fn sweep(degrees: f32) -> f32 {
    degrees.clamp(0.0, 360.0).to_radians()
}

/// The sweep of an exact shape: None when it is empty.
pub(crate) fn exact_sweep(degrees: f32) -> Option<f32> {
    let phi = sweep(degrees);
    (phi > 0.0).then_some(phi)
}

/// Roots of a t^2 + b t + c with the discriminant computed as pbrt-v4 does,
/// 4a (r + l)(r - l) with l the distance from the centre to the closest point on the ray,
/// which loses far less precision than b^2 - 4ac for distant or grazing rays.
pub(crate) fn quadratic_roots(
    a: f32,
    b: f32,
    c: f32,
    radius: f32,
    closest: f32,
) -> Option<(f32, f32)> {
    let discrim = 4.0 * a * (radius + closest) * (radius - closest);
    if discrim < 0.0 || a == 0.0 {
        return None;
    }
    let root = discrim.sqrt();
    let q = if b < 0.0 {
        -0.5 * (b - root)
    } else {
        -0.5 * (b + root)
    };
    let (t0, t1) = (q / a, c / q);
    Some(if t0 > t1 { (t1, t0) } else { (t0, t1) })
}

/// Whether a surface swept through `phi_max` is cut by it: a full turn clips nothing, as
/// [`phi_of`] is at most TAU (the intersection tests skip the azimuth then).
pub(crate) fn cut_in_phi(phi_max: f32) -> bool {
    phi_max < TAU
}

/// Whether `p` lies past `phi_max` in azimuth, on a surface cut short of a full turn (without
/// an atan2 on a whole one).
pub(crate) fn beyond_phi(p: Vec3A, phi_max: f32) -> bool {
    cut_in_phi(phi_max) && phi_of(p) > phi_max
}

/// The azimuth of `p` about z, in [0, TAU].
pub(crate) fn phi_of(p: Vec3A) -> f32 {
    let phi = atan2(p.y, p.x);
    if phi < 0.0 {
        phi + TAU
    } else {
        phi
    }
}

/// d p / d u for a surface swept around z with u = phi / phi_max.
pub(crate) fn u_tangent(p: Vec3A, phi_max: f32) -> Vec3A {
    Vec3A::new(-phi_max * p.y, phi_max * p.x, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The intersection tests skip the azimuth of a shape swept through a full turn: that
    /// must clip nothing, so no azimuth may exceed a full turn as the scene gives it (360
    /// degrees), even just below the +x axis where it wraps.
    #[test]
    fn a_full_turn_clips_no_azimuth() {
        let full_turn = sweep(360.0);
        assert!(!cut_in_phi(full_turn));
        assert!(cut_in_phi(sweep(359.99)));
        for k in 0u32..255 {
            let below_x = -f32::from_bits(1 + k * 0x0040_0000).min(1e-3);
            for p in [
                Vec3A::new(1.0, below_x, 0.0),
                Vec3A::new(-1.0, below_x, 0.0),
            ] {
                assert!(phi_of(p) <= full_turn, "{p}: {}", phi_of(p));
            }
        }
    }
}
