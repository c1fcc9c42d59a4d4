//! Fresnel reflectance: exact dielectric and conductor (complex index) formulas, and Schlick's
//! approximation from a normal-incidence reflectance.

use glam::Vec3;

/// Unpolarised reflectance of a dielectric interface for light arriving at `cos_i` from the
/// side the normal points to (negative: from inside); `eta` = n_inside / n_outside.
/// 1 under total internal reflection.
pub fn dielectric(cos_i: f32, eta: f32) -> f32 {
    let mut cos_i = cos_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// A complex number, just enough for the conductor Fresnel equations.
#[derive(Clone, Copy, Debug)]
struct Complex {
    re: f32,
    im: f32,
}

impl Complex {
    const fn new(re: f32, im: f32) -> Self {
        Self { re, im }
    }

    fn norm(self) -> f32 {
        self.re * self.re + self.im * self.im
    }

    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }

    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }

    fn mul(self, o: Self) -> Self {
        Self::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }

    fn scale(self, s: f32) -> Self {
        Self::new(self.re * s, self.im * s)
    }

    fn div(self, o: Self) -> Self {
        let scale = 1.0 / o.norm();
        Self::new(
            scale * (self.re * o.re + self.im * o.im),
            scale * (self.im * o.re - self.re * o.im),
        )
    }

    /// Principal square root, computed without cancellation (as in pbrt-v4).
    fn sqrt(self) -> Self {
        let n = self.norm().sqrt();
        if n == 0.0 {
            return Self::new(0.0, 0.0);
        }
        let t1 = (0.5 * (n + self.re.abs())).sqrt();
        let t2 = 0.5 * self.im / t1;
        if self.re >= 0.0 {
            Self::new(t1, t2)
        } else {
            Self::new(t2.abs(), t1.copysign(self.im))
        }
    }
}

/// Reflectance of a conductor with complex index eta + i k (relative to the outside medium),
/// for light arriving from outside at `cos_i`.
fn conductor_channel(cos_i: f32, eta: f32, k: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let eta = Complex::new(eta, k);
    let one = Complex::new(1.0, 0.0);
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = Complex::new(sin2_i, 0.0).div(eta.mul(eta));
    let cos_t = one.sub(sin2_t).sqrt();
    let ci = Complex::new(cos_i, 0.0);
    let r_parallel = eta.scale(cos_i).sub(cos_t).div(eta.scale(cos_i).add(cos_t));
    let r_perpendicular = ci.sub(eta.mul(cos_t)).div(ci.add(eta.mul(cos_t)));
    0.5 * (r_parallel.norm() + r_perpendicular.norm())
}

/// Conductor reflectance per RGB channel.
pub fn conductor(cos_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    Vec3::new(
        conductor_channel(cos_i, eta.x, k.x),
        conductor_channel(cos_i, eta.y, k.y),
        conductor_channel(cos_i, eta.z, k.z),
    )
}

/// Schlick's approximation with normal-incidence reflectance `r0`.
pub fn schlick(cos_i: f32, r0: Vec3) -> Vec3 {
    let m = (1.0 - cos_i.abs()).clamp(0.0, 1.0);
    let m2 = m * m;
    r0 + (Vec3::ONE - r0) * (m2 * m2 * m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_normal_incidence_is_squared_index_contrast() {
        assert!((dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        // Seen from inside the same interface reflects the same at normal incidence.
        assert!((dielectric(-1.0, 1.5) - 0.04).abs() < 1e-6);
        assert_eq!(dielectric(1.0, 1.0), 0.0);
    }

    #[test]
    fn dielectric_total_internal_reflection_beyond_critical_angle() {
        let critical = libm::asinf(1.0f32 / 1.5);
        assert_eq!(dielectric(-libm::cosf(critical + 0.01), 1.5), 1.0);
        assert!(dielectric(-libm::cosf(critical - 0.01), 1.5) < 1.0);
        // Grazing incidence from outside reflects everything.
        assert!(dielectric(1e-4, 1.5) > 0.99);
    }

    #[test]
    fn conductor_with_no_absorption_matches_dielectric() {
        for cos in [1.0f32, 0.8, 0.5, 0.2, 0.05] {
            let c = conductor(cos, Vec3::splat(1.7), Vec3::ZERO);
            assert!((c.x - dielectric(cos, 1.7)).abs() < 1e-5, "cos {cos}: {c}");
        }
    }

    #[test]
    fn conductor_normal_incidence_matches_closed_form() {
        // R(0) = ((eta-1)^2 + k^2) / ((eta+1)^2 + k^2); gold-like values.
        let (eta, k) = (0.2f32, 3.0f32);
        let expected = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
        let r = conductor(1.0, Vec3::splat(eta), Vec3::splat(k));
        assert!((r.x - expected).abs() < 1e-5, "{} vs {expected}", r.x);
        assert!(conductor(1e-3, Vec3::splat(eta), Vec3::splat(k)).x > 0.99);
    }

    #[test]
    fn schlick_interpolates_between_r0_and_one() {
        let r0 = Vec3::new(0.04, 0.5, 1.0);
        assert!((schlick(1.0, r0) - r0).length() < 1e-7);
        assert!((schlick(0.0, r0) - Vec3::ONE).length() < 1e-7);
    }
}
