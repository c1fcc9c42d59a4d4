//! The lobe of `null`: not a surface at all; a ray goes on through it unchanged.

use glam::{Vec2, Vec3};

use super::lobe::Lobe;
use super::sample::LocalSample;

#[derive(Clone, Copy, Debug)]
pub struct PassThrough;

impl Lobe for PassThrough {
    fn is_specular(&self) -> bool {
        true
    }

    fn albedo_hint(&self, _cos_o: f32) -> Vec3 {
        Vec3::ZERO
    }

    fn f(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        Vec3::ZERO
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, _wo: Vec3, _u_lobe: f32, _u: Vec2) -> Option<LocalSample> {
        None
    }
}
