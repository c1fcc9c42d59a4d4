//! Directions in the local shading frame, where z is the shading normal: the trigonometry,
//! reflection, refraction and hemisphere sampling every BxDF shares.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

use glam::{Vec2, Vec3};

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
    let o = u * 2.0 - Vec2::ONE;
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    Vec2::new(theta.cos(), theta.sin()) * r
}

/// The polar mapping of the unit square onto the unit disk (what visible-normal sampling's
/// warp expects).
pub fn sample_disk_polar(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let theta = 2.0 * PI * u.y;
    Vec2::new(theta.cos(), theta.sin()) * r
}

/// Cosine-weighted direction in the upper hemisphere (Malley's method).
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = sample_disk_concentric(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

pub fn cosine_hemisphere_pdf(abs_cos: f32) -> f32 {
    abs_cos * FRAC_1_PI
}
