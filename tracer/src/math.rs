//! Small geometric helpers shared by every module.

use glam::{Affine3A, Mat4, Vec3};

use crate::vec3_lanes;

#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    /// Unit length.
    pub dir: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self { origin, dir }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// A cone of directions: its axis (unit) and its half angle (radians; pi or more is every
/// direction).
#[derive(Clone, Copy, Debug)]
pub struct Cone {
    pub axis: Vec3,
    pub half: f32,
}

/// An orthonormal basis with `n` as its z axis; converts between world and local shading space.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// A frame around `n` with `s` along `tangent` projected onto the plane (any tangent if
    /// that is degenerate).
    pub fn from_normal_tangent(n: Vec3, tangent: Vec3) -> Self {
        let s = tangent - n * n.dot(tangent);
        let len2 = s.length_squared();
        if len2 > 1e-12 && len2.is_finite() {
            let s = s / len2.sqrt();
            Self {
                s,
                t: n.cross(s),
                n,
            }
        } else {
            Self::from_normal(n)
        }
    }

    /// Duff et al. 2017, "Building an Orthonormal Basis, Revisited".
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { s, t, n }
    }

    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// Luminance of linear sRGB / Rec.709 primaries.
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Offsets a ray origin along the geometric normal so it does not re-hit its own surface; the
/// offset scales with the magnitude of the point (floating-point error grows with it).
/// One lane of [`vec3_lanes::offset_origin`], which a packet's lanes run: the same bits.
#[inline(always)]
pub fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    Vec3::from_array(vec3_lanes::offset_origin::<f32>(
        p.to_array(),
        ng.to_array(),
        dir.to_array(),
    ))
}

/// `m`'s inverse, computed in f64 and rounded back. glam's f32 `Mat4` and `Affine3A` inverses
/// take their SSE2, NEON or scalar form by target, each with its own order of operations, so
/// their last bits differ between x86-64 and aarch64 workers; glam's f64 matrices are the same
/// scalar code on every target. clippy.toml
/// keeps the f32 inverses out.
pub fn inverse(m: &Mat4) -> Mat4 {
    m.as_dmat4().inverse().as_mat4()
}

/// [`inverse`] of an affine transform.
pub fn affine_inverse(a: &Affine3A) -> Affine3A {
    a.as_daffine3().inverse().as_affine3a()
}

/// `x.floor()` as an integer, for |x| < 2^31, without the libm call baseline x86-64 makes for
/// `floor` (it has no rounding instruction before SSE4.1): in the filter's and the texel
/// lookups' hot paths that call was a few percent of a render. The same value as `floor`
/// wherever that holds (an f32 of magnitude 2^23 or more is an integer, so the truncation is
/// exact there); NaN gives 0, as `floor(NaN) as i64` does.
pub fn floor_to_int(x: f32) -> i64 {
    let t = x as i64;
    t - i64::from(t as f32 > x)
}

/// `n` as a float, through u32: float from u64 takes several instructions on x86-64 without
/// AVX-512, and the tables and counts this is for stay below 2^32 (where the value is the same).
pub fn count_f32(n: usize) -> f32 {
    n as u32 as f32
}

/// The entry of 0..n (n > 0) that `x`, in entries, lies in: `(x as usize).min(n - 1)` through
/// u32, for the same reason (the same value for n up to 2^32; NaN and negative x give 0).
pub fn bin_at(x: f32, n: usize) -> usize {
    (x as u32 as usize).min(n - 1)
}

/// `y.atan2(x)` within 3e-7 radians, without a libm call (which takes some 100 instructions
/// through glibc's wrappers): Cephes' single-precision arctangent on the octant, `min / max` of
/// the magnitudes, reduced around tan(pi/8), then unfolded by the larger magnitude and the
/// signs. Signed zeros and NaN come out as libm's do. An environment map takes two for every
/// ray that escapes to it, an analytic shape one for every ray that reaches it.
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    const TAN_PI_8: f32 = 0.414_213_57;
    let (ax, ay) = (x.abs(), y.abs());
    let (small, large) = if ay > ax { (ax, ay) } else { (ay, ax) };
    let a = if large == 0.0 { 0.0 } else { small / large };
    let (base, a) = if a > TAN_PI_8 {
        (FRAC_PI_4, (a - 1.0) / (a + 1.0))
    } else {
        (0.0, a)
    };
    let z = a * a;
    let poly = ((0.080_537_445 * z - 0.138_776_86) * z + 0.199_777_1) * z - 0.333_329_5;
    let mut r = base + (poly * z * a + a);
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x.is_sign_negative() {
        r = PI - r;
    }
    if y.is_sign_negative() {
        -r
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_and_round_trips() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::new(0.3, -0.5, 0.8).normalize()] {
            let f = Frame::from_normal(n);
            assert!(f.s.dot(f.t).abs() < 1e-6 && f.s.dot(f.n).abs() < 1e-6);
            assert!((f.s.length() - 1.0).abs() < 1e-5 && (f.t.length() - 1.0).abs() < 1e-5);
            let v = Vec3::new(0.1, 0.7, -0.2);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
            assert!((f.to_local(n) - Vec3::Z).length() < 1e-5);
        }
    }

    /// The u32 routes give what the usize conversions give, for the sizes they serve.
    #[test]
    fn bins_and_counts_through_u32_equal_the_usize_conversions() {
        for n in [1usize, 2, 3, 256, 400, 1 << 20, u32::MAX as usize] {
            assert_eq!(count_f32(n), n as f32);
            for x in [
                f32::NAN,
                f32::NEG_INFINITY,
                -1.5,
                -0.0,
                0.0,
                0.999_999_94,
                1.0,
                255.5,
                256.0,
                399.999_97,
                1.0e9,
                5.0e9,
                f32::INFINITY,
            ] {
                assert_eq!(bin_at(x, n), (x as usize).min(n - 1), "x {x} n {n}");
            }
        }
    }

    #[test]
    fn floor_to_int_is_floor() {
        let cases = [
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.999_999_8,
            -2.000_000_2,
            8_388_607.5,
            -8_388_607.5,
            16_777_217.0,
            -1.0e9,
            1.0e9,
            2_147_483_520.0,
            -2_147_483_520.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
        ];
        for x in cases {
            assert_eq!(floor_to_int(x), x.floor() as i64, "{x}");
        }
        // Around every integer and half of [-64, 64]: the value, and one float step either side.
        for k in -128..=128 {
            let x = k as f32 / 2.0;
            for v in [x.next_down(), x, x.next_up()] {
                assert_eq!(floor_to_int(v), v.floor() as i64, "{v}");
            }
        }
        assert_eq!(floor_to_int(f32::NAN), 0);
    }

    /// The f64 inverses undo an exporter's kind of transform (turned, unevenly scaled, moved)
    /// to within float rounding, as matrices and as affine transforms.
    #[test]
    fn inverses_undo_the_transform() {
        let m = Mat4::from_scale_rotation_translation(
            Vec3::new(0.5, 2.0, 0.3),
            glam::Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            Vec3::new(4.0, -2.5, 0.7),
        );
        assert!((inverse(&m) * m).abs_diff_eq(Mat4::IDENTITY, 1e-5));
        assert!((m * inverse(&m)).abs_diff_eq(Mat4::IDENTITY, 1e-5));
        let a = Affine3A::from_mat4(m);
        let p = Vec3::new(-1.5, 0.25, 3.0);
        let back = affine_inverse(&a).transform_point3(a.transform_point3(p));
        assert!(back.abs_diff_eq(p, 1e-5), "{back}");
        assert!(Mat4::from(affine_inverse(&a)).abs_diff_eq(inverse(&m), 1e-6));
    }

    /// Against f64's atan2 around the whole circle (every 1e-4 rad, at radii from 1e-6 to 1e6,
    /// and at the octant edges), the error stays under 3e-7 rad; the axes, signed zeros and
    /// NaN give what libm gives.
    #[test]
    fn atan2_is_within_its_error_of_libm() {
        let mut worst = 0.0f64;
        let mut check = |y: f32, x: f32| {
            let exact = libm::atan2(f64::from(y), f64::from(x));
            worst = worst.max((f64::from(atan2(y, x)) - exact).abs());
        };
        for k in 0..62_832 {
            let angle = k as f64 * 1e-4 - std::f64::consts::PI;
            for radius in [1e-6f64, 0.37, 1.0, 3.3e3, 1e6] {
                check(
                    (radius * libm::sin(angle)) as f32,
                    (radius * libm::cos(angle)) as f32,
                );
            }
        }
        for a in [
            0.414_213_5f32,
            0.414_213_57,
            0.414_213_6,
            1.0,
            0.999_999_9,
            1.000_000_1,
        ] {
            for (sy, sx) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                check(sy * a, sx);
                check(sy, sx * a);
            }
        }
        assert!(worst < 3e-7, "worst error {worst:e}");
        for (y, x) in [
            (0.0f32, 1.0f32),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (0.0, 0.0),
            (-0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (1.0, -0.0),
        ] {
            assert_eq!(
                atan2(y, x).to_bits(),
                libm::atan2f(y, x).to_bits(),
                "atan2({y}, {x})"
            );
        }
        assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
    }
}
