//! Small geometric helpers shared by every module.

use glam::Vec3;

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
pub fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let eps = 1e-4 * (1.0 + p.abs().max_element());
    if dir.dot(ng) >= 0.0 {
        p + ng * eps
    } else {
        p - ng * eps
    }
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
}
