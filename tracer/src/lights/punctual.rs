//! Lights with a delta distribution: point, spot (LuxRender's smoothstep falloff) and distant.

use std::f32::consts::PI;

use glam::Vec3;

use crate::math::luminance;

/// Direction and radiance of a delta light as seen from a point.
pub(super) struct DeltaSample {
    pub wi: Vec3,
    pub li: Vec3,
    pub dist: f32,
}

pub(super) struct PointLight {
    pub position: Vec3,
    pub intensity: Vec3,
}

impl PointLight {
    pub fn sample(&self, from: Vec3) -> Option<DeltaSample> {
        let to_light = self.position - from;
        let dist2 = to_light.length_squared();
        (dist2 > 0.0).then(|| {
            let dist = dist2.sqrt();
            DeltaSample {
                wi: to_light / dist,
                li: self.intensity / dist2,
                dist,
            }
        })
    }

    pub fn power(&self) -> f32 {
        4.0 * PI * luminance(self.intensity)
    }
}

pub(super) struct SpotLight {
    point: PointLight,
    direction: Vec3,
    /// cos(coneangle): no light outside.
    cos_total: f32,
    /// cos(coneangle - conedeltaangle): full intensity inside.
    cos_falloff_start: f32,
}

impl SpotLight {
    /// Angles in degrees.
    pub fn new(
        position: Vec3,
        direction: Vec3,
        intensity: Vec3,
        cone_angle: f32,
        cone_delta_angle: f32,
    ) -> Self {
        let cone = cone_angle.clamp(0.0, 180.0);
        let start = (cone - cone_delta_angle.max(0.0)).max(0.0);
        Self {
            point: PointLight {
                position,
                intensity,
            },
            direction: direction.normalize_or(Vec3::Z),
            cos_total: cone.to_radians().cos(),
            cos_falloff_start: start.to_radians().cos(),
        }
    }

    pub fn sample(&self, from: Vec3) -> Option<DeltaSample> {
        let s = self.point.sample(from)?;
        let falloff = self.falloff(-s.wi.dot(self.direction));
        (falloff > 0.0).then(|| DeltaSample {
            li: s.li * falloff,
            ..s
        })
    }

    /// Smoothstep from the cone's edge to where the falloff starts.
    fn falloff(&self, cos_theta: f32) -> f32 {
        if self.cos_falloff_start <= self.cos_total {
            return if cos_theta >= self.cos_total {
                1.0
            } else {
                0.0
            };
        }
        let t = ((cos_theta - self.cos_total) / (self.cos_falloff_start - self.cos_total))
            .clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    }

    /// pbrt-v4's estimate: the full cone to where the falloff starts, half of the falloff band.
    pub fn power(&self) -> f32 {
        luminance(self.point.intensity)
            * 2.0
            * PI
            * (1.0 - 0.5 * (self.cos_falloff_start + self.cos_total))
    }
}

pub(super) struct DistantLight {
    pub to_light: Vec3,
    pub radiance: Vec3,
}

impl DistantLight {
    pub fn sample(&self) -> DeltaSample {
        DeltaSample {
            wi: self.to_light,
            li: self.radiance,
            dist: f32::INFINITY,
        }
    }

    /// The flux through a disk of the scene's size.
    pub fn power(&self, scene_radius: f32) -> f32 {
        PI * scene_radius * scene_radius * luminance(self.radiance)
    }
}
