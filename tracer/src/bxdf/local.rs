//! Directions in the local shading frame, where z is the shading normal: the trigonometry,
//! reflection, refraction and hemisphere sampling every BxDF shares.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_4, PI};

use glam::{Vec2, Vec3};

use crate::lanes::{sin_cos_quarter, Lanes};

pub fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// The mirror image of `w` about the normal `n` (both pointing away from the surface).
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    -w + n * (2.0 * w.dot(n))
}

/// Mirrors `w` about the local xy plane, keeping its azimuth.
pub fn flip_z(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}

/// Refracts `w` (pointing away from the surface) through the interface with normal `n` and
/// relative index `eta` = n_inside / n_outside, where `n` points outside. Returns the
/// transmitted direction and the index ratio actually crossed (`eta` entering, 1/eta leaving);
/// None under total internal reflection.
pub fn refract(w: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = w.dot(n);
    let (mut eta, mut n) = (eta, n);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-w / eta + n * (cos_i / eta - cos_t), eta))
}

/// Shirley-Chiu concentric mapping of the unit square onto the unit disk (keeps strata
/// compact, which the Sobol sampler's 2D stratification benefits from).
pub fn sample_disk_concentric(u: Vec2) -> Vec2 {
    Vec2::from(concentric_disk(u.to_array()))
}

/// [`sample_disk_concentric`] in lanes, and what it runs on one: the same bits on every lane
/// type. The angle is pi/4 times a ratio within [-1, 1], whose sine and cosine are the disk
/// point, or its cosine and sine on the half where the angle was pi/2 less it.
#[inline(always)]
pub fn concentric_disk<L: Lanes>(u: [L; 2]) -> [L; 2] {
    let (one, two) = (L::splat(1.0), L::splat(2.0));
    let (x, y) = (u[0] * two - one, u[1] * two - one);
    let (ax, ay) = (x.abs(), y.abs());
    let centre = !(L::splat(0.0).lt(ax) | L::splat(0.0).lt(ay));
    let across = ay.lt(ax);
    let r = L::select(across, x, y);
    let ratio = L::select(across, y, x) / r;
    let (sin, cos) = sin_cos_quarter(L::splat(FRAC_PI_4) * ratio);
    let zero = L::splat(0.0);
    [
        L::select(centre, zero, L::select(across, cos, sin) * r),
        L::select(centre, zero, L::select(across, sin, cos) * r),
    ]
}

/// The polar mapping of the unit square onto the unit disk (what visible-normal sampling's
/// warp expects).
pub fn sample_disk_polar(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let theta = 2.0 * PI * u.y;
    Vec2::new(libm::cosf(theta), libm::sinf(theta)) * r
}

/// Cosine-weighted direction in the upper hemisphere (Malley's method).
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    Vec3::from(cosine_hemisphere(u.to_array()))
}

/// [`sample_cosine_hemisphere`] in lanes, and what it runs on one.
#[inline(always)]
pub fn cosine_hemisphere<L: Lanes>(u: [L; 2]) -> [L; 3] {
    let [x, y] = concentric_disk(u);
    let z = (L::splat(1.0) - (x * x + y * y)).max(L::splat(0.0)).sqrt();
    [x, y, z]
}

pub fn cosine_hemisphere_pdf(abs_cos: f32) -> f32 {
    abs_cos * FRAC_1_PI
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The disk mapping stays inside the unit disk and is Shirley and Chiu's, computed with
    /// double-precision trigonometry, to within a few ulp.
    #[test]
    fn the_concentric_disk_is_shirley_and_chius() {
        let steps = 200;
        for i in 0..steps {
            for j in 0..steps {
                let u = Vec2::new(i as f32, j as f32) / steps as f32;
                let d = sample_disk_concentric(u);
                assert!(d.length() <= 1.0 + 1e-6, "{u} -> {d}");
                let (x, y) = (2.0 * f64::from(u.x) - 1.0, 2.0 * f64::from(u.y) - 1.0);
                let quarter = std::f64::consts::FRAC_PI_4;
                let (r, theta) = if x.abs() > y.abs() {
                    (x, quarter * (y / x))
                } else if y != 0.0 {
                    (y, 2.0 * quarter - quarter * (x / y))
                } else {
                    (0.0, 0.0)
                };
                let exact = (r * libm::cos(theta), r * libm::sin(theta));
                let error = libm::hypot(f64::from(d.x) - exact.0, f64::from(d.y) - exact.1);
                assert!(error < 4e-7, "{u} -> {d}, exactly {exact:?}");
            }
        }
        assert_eq!(sample_disk_concentric(Vec2::splat(0.5)), Vec2::ZERO);
        assert!((sample_disk_concentric(Vec2::new(1.0, 0.5)) - Vec2::X).length() < 1e-6);
    }
}
