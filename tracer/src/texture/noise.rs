//! Perlin noise and its sums, as LuxRender 1.x defines them (`core/texture.cpp`, after pbrt):
//! gradient noise on the integer lattice with Perlin's "improved noise" permutation and
//! quintic fade, fBm (signed octaves) and turbulence (absolute octaves). Every procedural
//! texture that uses them (fbm, wrinkled, windy, marble, dots) reads them from here, so a
//! pattern lands where LuxRender puts it.
//!
//! LuxRender computes the octave count from the ray differentials; it evaluates its textures
//! with zero differentials, which gives exactly `octaves` full octaves and no partial one (and
//! turbulence's correction term for missing octaves is then 0). That is the case implemented.

use glam::Vec3;

/// Each octave's frequency is this times the previous one (LuxRender's 1.99, not 2, so
/// lattice points of successive octaves do not line up).
pub const LACUNARITY: f32 = 1.99;

/// Ken Perlin's permutation of 0..=255 from his reference "improved noise" (2002), which
/// LuxRender uses; read twice in a row so lookups need no wrap.
const PERM: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69,
    142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219,
    203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175,
    74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60, 211, 133, 230,
    220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76,
    132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173,
    186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163,
    70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232,
    178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162,
    241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204,
    176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141,
    128, 195, 78, 66, 215, 61, 156, 180,
];

fn perm(i: usize) -> usize {
    PERM[i & 255] as usize
}

/// The dot product of the lattice point's pseudo-random gradient (one of 12 cube-edge
/// directions, 4 repeated) with the offset from it.
fn grad(x: usize, y: usize, z: usize, d: Vec3) -> f32 {
    let h = perm(perm(perm(x) + y) + z) & 15;
    let u = if h < 8 || h == 12 || h == 13 {
        d.x
    } else {
        d.y
    };
    let v = if h < 4 || h == 12 || h == 13 {
        d.y
    } else {
        d.z
    };
    (if h & 1 != 0 { -u } else { u }) + (if h & 2 != 0 { -v } else { v })
}

/// 6t^5 - 15t^4 + 10t^3: zero first and second derivatives at the lattice.
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

fn lerp(t: f32, a: f32, b: f32) -> f32 {
    a + t * (b - a)
}

/// Perlin gradient noise at `p`: continuous, 0 on every lattice point, roughly in [-1, 1]
/// with mean 0. Non-finite input gives 0.
pub fn noise(p: Vec3) -> f32 {
    if !p.is_finite() {
        return 0.0;
    }
    let cell = p.floor();
    let d = p - cell;
    // Wrapping to the 256-periodic lattice first keeps huge coordinates in range.
    let [ix, iy, iz] = cell.to_array().map(|c| c.rem_euclid(256.0) as usize);
    let corner = |dx: usize, dy: usize, dz: usize| {
        grad(
            ix + dx,
            iy + dy,
            iz + dz,
            d - Vec3::new(dx as f32, dy as f32, dz as f32),
        )
    };
    let (wx, wy, wz) = (fade(d.x), fade(d.y), fade(d.z));
    let x00 = lerp(wx, corner(0, 0, 0), corner(1, 0, 0));
    let x10 = lerp(wx, corner(0, 1, 0), corner(1, 1, 0));
    let x01 = lerp(wx, corner(0, 0, 1), corner(1, 0, 1));
    let x11 = lerp(wx, corner(0, 1, 1), corner(1, 1, 1));
    lerp(wz, lerp(wy, x00, x10), lerp(wy, x01, x11))
}

/// LuxRender's 2D noise call `Noise(x, y)`: the 3D noise on the plane z = 0.5.
pub fn noise2(x: f32, y: f32) -> f32 {
    noise(Vec3::new(x, y, 0.5))
}

/// Fractional Brownian motion: sum over `octaves` of omega^i x noise(1.99^i x p).
pub fn fbm(p: Vec3, omega: f32, octaves: u32) -> f32 {
    octave_sum(p, omega, octaves, |n| n)
}

/// Turbulence: fBm of |noise|, always >= 0.
pub fn turbulence(p: Vec3, omega: f32, octaves: u32) -> f32 {
    octave_sum(p, omega, octaves, f32::abs)
}

fn octave_sum(p: Vec3, omega: f32, octaves: u32, shape: impl Fn(f32) -> f32) -> f32 {
    let (mut sum, mut lambda, mut o) = (0.0, 1.0, 1.0);
    for _ in 0..octaves {
        sum += o * shape(noise(lambda * p));
        lambda *= LACUNARITY;
        o *= omega;
    }
    sum
}

/// The most octaves a texture may ask for: beyond ~30 the frequency overflows f32 precision
/// anyway, and the bound keeps a hostile file from stalling every lookup.
pub const MAX_OCTAVES: u32 = 32;
