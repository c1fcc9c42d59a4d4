//! Which lamps a narrow cone of directions may reach: the bounding spheres of the area lights,
//! tested against a cone from a shading point. The path tracer asks it where a glossy lobe
//! could show a lamp's highlight (the vertices worth more BSDF samples, see
//! [`crate::integrator::GLOSSY_SPLIT`]); an answer of "maybe" costs only samples, so the test
//! may be loose but never misses a lamp inside the cone.

use glam::Vec3;

use crate::math::Cone;

/// Lamps tested one by one; a scene with more says "maybe" everywhere (a split vertex costs a
/// few rays, a test per lamp at every glossy vertex would cost more).
pub const MAX_LAMP_SPHERES: usize = 64;

/// The lamps' bounding spheres.
#[derive(Clone, Debug, Default)]
pub struct LampSpheres {
    spheres: Vec<(Vec3, f32)>,
    /// More lamps than [`MAX_LAMP_SPHERES`]: every cone may reach one.
    too_many: bool,
}

impl LampSpheres {
    /// From the lamps' bounding boxes.
    pub fn new(boxes: &[(Vec3, Vec3)]) -> Self {
        if boxes.len() > MAX_LAMP_SPHERES {
            return Self {
                spheres: Vec::new(),
                too_many: true,
            };
        }
        let spheres = boxes
            .iter()
            .map(|&(lo, hi)| (0.5 * (lo + hi), 0.5 * (hi - lo).length()))
            .collect();
        Self {
            spheres,
            too_many: false,
        }
    }

    /// Whether a lamp's sphere overlaps `cone` from `p`: the angle between the axis and the
    /// sphere's centre is below the cone's half angle plus the sphere's angular radius.
    pub fn may_reach(&self, p: Vec3, cone: &Cone) -> bool {
        self.too_many
            || self.spheres.iter().any(|&(centre, radius)| {
                let to_centre = centre - p;
                let dist = to_centre.length();
                if dist <= radius {
                    return true;
                }
                let reach = cone.half + libm::asinf(radius / dist);
                reach >= std::f32::consts::PI
                    || cone.axis.dot(to_centre) >= libm::cosf(reach) * dist
            })
    }

    /// Whether a ray from `p` along the unit `dir` may hit a lamp: it passes within a lamp's
    /// sphere (its closest approach to the centre, ahead of `p`, is within the radius; or `p` is
    /// inside). Without [`Self::may_reach`]'s arcsine and cosine: a glossy split asks this for
    /// each of its samples. The radius is widened by a thousandth against rounding: a yes only
    /// costs a traced ray.
    pub fn may_reach_along(&self, p: Vec3, dir: Vec3) -> bool {
        self.too_many
            || self.spheres.iter().any(|&(centre, radius)| {
                let to_centre = centre - p;
                let reach = radius * 1.001;
                let dist_sq = to_centre.length_squared();
                if dist_sq <= reach * reach {
                    return true;
                }
                // The offset of the centre from the ray's line, not dist^2 - along^2, which
                // cancels for a lamp far away compared with its size.
                let along = dir.dot(to_centre);
                along > 0.0 && (to_centre - dir * along).length_squared() <= reach * reach
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random cones from the origin: every one whose angle to the lamp's sphere is within its
    /// half angle plus the sphere's angular radius gets a yes, every one clearly wider of it a
    /// no, and a cone of every direction a yes.
    #[test]
    fn a_cone_reaching_a_lamp_is_never_missed() {
        let lamp = (Vec3::new(-0.5, -0.5, 4.0), Vec3::new(0.5, 0.5, 4.0));
        let cones = LampSpheres::new(&[lamp]);
        let p = Vec3::ZERO;
        let (centre, radius) = (Vec3::new(0.0, 0.0, 4.0), 0.5f32.sqrt());
        let mut state = 12345u64;
        let mut next = || {
            state = crate::sampler::mix64(state.wrapping_add(0x9e37_79b9_7f4a_7c15));
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let (mut reached, mut missed) = (0, 0);
        for _ in 0..20_000 {
            let axis = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
            let half = next() * 0.8;
            let cone = Cone { axis, half };
            let to_centre = (centre - p).normalize();
            let angle = libm::acosf(axis.dot(to_centre).clamp(-1.0, 1.0));
            let sphere_angle = libm::asinf(radius / 4.0);
            let touches = angle <= half + sphere_angle - 1e-3;
            let says = cones.may_reach(p, &cone);
            if touches {
                assert!(says, "axis {axis} half {half}");
                reached += 1;
            } else if angle > half + sphere_angle + 1e-3 {
                assert!(!says, "axis {axis} half {half}");
                missed += 1;
            }
        }
        assert!(reached > 100 && missed > 100, "{reached} {missed}");
        let wide = Cone {
            axis: Vec3::NEG_Z,
            half: 3.2,
        };
        assert!(cones.may_reach(p, &wide));
    }

    /// Rays from shading points around a 1x1 lamp at every point of the lamp (a glossy split's
    /// samples that hit it) are all said to reach it; rays turned well away from it are not.
    #[test]
    fn a_ray_at_a_lamp_is_never_missed() {
        let lamp = (Vec3::new(-0.5, -0.5, 4.0), Vec3::new(0.5, 0.5, 4.0));
        let cones = LampSpheres::new(&[lamp]);
        let mut state = 777u64;
        let mut next = || {
            state = crate::sampler::mix64(state.wrapping_add(0x9e37_79b9_7f4a_7c15));
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..20_000 {
            let p = Vec3::new(next() * 6.0 - 3.0, next() * 6.0 - 3.0, next() * 3.0);
            let target = Vec3::new(next() - 0.5, next() - 0.5, 4.0);
            let dir = (target - p).normalize();
            assert!(cones.may_reach_along(p, dir), "from {p} towards {target}");
            // Every shading point is below the lamp's sphere: the reverse points away from it.
            let away = -dir;
            assert!(
                !cones.may_reach_along(p, away),
                "from {p} away along {away}"
            );
        }
        // From two thousand lamp sizes away, rays at the lamp's corners (on its sphere) are
        // still said to reach it, and rays passing 1% of its radius outside the sphere are not.
        let far = LampSpheres::new(&[(Vec3::new(-0.5, -0.5, 2000.0), Vec3::new(0.5, 0.5, 2000.0))]);
        let radius = 0.5f32.sqrt();
        for corner in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            let p = Vec3::new(3.0, -2.0, 0.0);
            let to_corner = Vec3::new(corner.0, corner.1, 2000.0) - p;
            assert!(
                far.may_reach_along(p, to_corner.normalize()),
                "corner {corner:?}"
            );
            let outside = Vec3::new(corner.0, corner.1, 0.0).normalize() * radius * 1.01;
            let past = (Vec3::new(outside.x, outside.y, 2000.0) - p).normalize();
            assert!(!far.may_reach_along(p, past), "past corner {corner:?}");
        }
    }
}
