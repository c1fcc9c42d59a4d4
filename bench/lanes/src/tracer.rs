//! The path tracer the variants share, written once over [`Lanes`]: a packet is `L::N`
//! consecutive samples of one pixel, advanced a vertex at a time under a mask of live paths.
//!
//! The scene imitates depth-of-field-high (our numbers, not its file): three matte spheres, a
//! floor and two walls with a bilinearly filtered checkerboard, a quad lamp, a thin-lens camera.
//! Next-event estimation with the power heuristic, cosine-weighted continuations, roulette from
//! the third vertex, depth 10. Random numbers are YAT's own (Owen-scrambled Sobol) drawn for a
//! packet at once by `yat_tracer::sampler::PacketSampler`, so a sample draws the same numbers in
//! every variant, and the numbers cost what they cost in YAT.

use glam::Vec3;
use yat_tracer::lanes::{Lanes, Mask, U32Lanes, MAX_LANES};
use yat_tracer::sampler::PacketSampler;

pub const MAX_DEPTH: usize = 10;
const RADIUS: f32 = 0.5;
/// Centres and albedos.
const SPHERES: [([f32; 3], [f32; 3]); 3] = [
    ([1.5, -2.0, 0.5], [0.1, 0.1, 0.8]),
    ([0.0, 0.0, 0.5], [0.1, 0.8, 0.1]),
    ([-1.5, 2.0, 0.5], [0.8, 0.1, 0.1]),
];
const LAMP_CENTRE: [f32; 3] = [4.16, -2.53, 4.0];
const LAMP_EDGE_1: [f32; 3] = [1.299, 0.75, 0.0];
const LAMP_EDGE_2: [f32; 3] = [-0.5304, 0.9186, 1.0607];
/// The side the lamp emits to.
const LAMP_NORMAL: [f32; 3] = [-0.353_553_4, 0.612_372_46, -std::f32::consts::FRAC_1_SQRT_2];
const LAMP_AREA: f32 = 2.25;
const LAMP_RADIANCE: f32 = 8.0;
const ID_FLOOR: u32 = 3;
const ID_BACK: u32 = 4;
const ID_LEFT: u32 = 5;
const ID_LAMP: u32 = 6;
const ID_MISS: u32 = 7;
const PI: f32 = std::f32::consts::PI;
const TEXELS: usize = 16;
/// Surfaces are offset by this along their normal, and hits nearer than it ignored.
const EPSILON: f32 = 1e-4;

/// How the closest hits are found: the same answers either way.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Traversal {
    /// Every lane's ray against every primitive, in lanes.
    Lanes,
    /// One live lane at a time through the scalar test, as a per-ray BVH traversal would run
    /// beside shading in lanes.
    ByLane,
}

pub struct Scene {
    /// Red, green and blue texels, row-major.
    texture: [Vec<f32>; 3],
    eye: [f32; 3],
    right: [f32; 3],
    up: [f32; 3],
    forward: [f32; 3],
    pub width: usize,
    pub height: usize,
}

impl Scene {
    pub fn new(width: usize, height: usize) -> Self {
        let texture = [0.8, 0.78, 0.75].map(|white| {
            let mut t = vec![0.04; TEXELS * TEXELS];
            for (i, texel) in t.iter_mut().enumerate() {
                if (i % TEXELS / 4 + i / TEXELS / 4).is_multiple_of(2) {
                    *texel = white;
                }
            }
            t
        });
        let eye = Vec3::new(1.33, -5.0, 1.5);
        let target = Vec3::new(1.075_113, -4.048_749, 1.326_352);
        let forward = (target - eye).normalize();
        let right = forward
            .cross(Vec3::new(-0.044_943, 0.167_731, 0.984_808))
            .normalize();
        let up = right.cross(forward);
        Scene {
            texture,
            eye: eye.to_array(),
            right: right.to_array(),
            up: up.to_array(),
            forward: forward.to_array(),
            width,
            height,
        }
    }
}

#[derive(Clone, Copy)]
struct V3<L> {
    x: L,
    y: L,
    z: L,
}

impl<L: Lanes> V3<L> {
    #[inline(always)]
    fn splat(a: [f32; 3]) -> Self {
        V3 {
            x: L::splat(a[0]),
            y: L::splat(a[1]),
            z: L::splat(a[2]),
        }
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
    #[inline(always)]
    fn scale(self, s: L) -> Self {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        V3 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }
    #[inline(always)]
    fn dot(self, o: Self) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    fn select(m: L::M, a: Self, b: Self) -> Self {
        V3 {
            x: L::select(m, a.x, b.x),
            y: L::select(m, a.y, b.y),
            z: L::select(m, a.z, b.z),
        }
    }
    #[inline(always)]
    fn neg(self) -> Self {
        V3::splat([0.0; 3]).sub(self)
    }
    #[inline(always)]
    fn normalize(self) -> Self {
        self.scale(L::splat(1.0) / self.dot(self).sqrt())
    }
}

/// sin and cos of `theta` in [0, 2 pi) by a polynomial (libm's would differ between lane types).
#[inline(always)]
fn sin_cos<L: Lanes>(theta: L) -> (L, L) {
    let zero = L::splat(0.0);
    let half_pi = L::splat(PI / 2.0);
    let x = theta - L::splat(PI);
    let folded = L::select(
        half_pi.lt(x),
        L::splat(PI) - x,
        L::select(x.lt(zero - half_pi), L::splat(-PI) - x, x),
    );
    let abs = x.max(zero - x);
    (
        zero - sin_near_zero(folded),
        zero - sin_near_zero(half_pi - abs),
    )
}

/// sin(y) for |y| <= pi/2 (Taylor to y^9: error below 4e-6).
#[inline(always)]
fn sin_near_zero<L: Lanes>(y: L) -> L {
    let y2 = y * y;
    y * (L::splat(1.0)
        + y2 * (L::splat(-1.0 / 6.0)
            + y2 * (L::splat(1.0 / 120.0)
                + y2 * (L::splat(-1.0 / 5040.0) + y2 * L::splat(1.0 / 362_880.0)))))
}

#[inline(always)]
fn within<L: Lanes>(a: L, lo: f32, hi: f32) -> L::M {
    L::splat(lo).le(a) & a.le(L::splat(hi))
}

struct Hit<L: Lanes> {
    t: L,
    id: L::U,
}

impl<L: Lanes> Hit<L> {
    /// Takes primitive `id` at distance `t` in the lanes of `m` where it is nearer.
    #[inline(always)]
    fn keep(&mut self, m: L::M, t: L, id: u32) {
        let m = m & L::splat(EPSILON).lt(t) & t.lt(self.t);
        self.t = L::select(m, t, self.t);
        self.id = L::U::select(m, L::U::splat(id), self.id);
    }
}

#[inline(always)]
fn closest<L: Lanes>(o: V3<L>, d: V3<L>) -> Hit<L> {
    let eps = L::splat(EPSILON);
    let zero = L::splat(0.0);
    let mut hit = Hit {
        t: L::splat(f32::INFINITY),
        id: L::U::splat(ID_MISS),
    };
    for (i, (centre, _)) in SPHERES.iter().enumerate() {
        let oc = o.sub(V3::splat(*centre));
        let b = oc.dot(d);
        let disc = b * b - (oc.dot(oc) - L::splat(RADIUS * RADIUS));
        let root = disc.max(zero).sqrt();
        let (near, far) = (zero - b - root, zero - b + root);
        let tp = L::select(eps.lt(near), near, far);
        hit.keep(zero.le(disc), tp, i as u32);
    }
    let floor = (zero - o.z) / d.z;
    let p = o.add(d.scale(floor));
    hit.keep(
        within(p.x, -5.0, 5.0) & within(p.y, -5.0, 5.0),
        floor,
        ID_FLOOR,
    );
    let back = (L::splat(5.0) - o.y) / d.y;
    let p = o.add(d.scale(back));
    hit.keep(
        within(p.x, -5.0, 5.0) & within(p.z, 0.0, 10.0),
        back,
        ID_BACK,
    );
    let left = (L::splat(-5.0) - o.x) / d.x;
    let p = o.add(d.scale(left));
    hit.keep(
        within(p.y, -5.0, 5.0) & within(p.z, 0.0, 10.0),
        left,
        ID_LEFT,
    );
    // The lamp, from either side.
    let n = V3::<L>::splat(LAMP_NORMAL);
    let lamp = V3::<L>::splat(LAMP_CENTRE).sub(o).dot(n) / d.dot(n);
    let q = o.add(d.scale(lamp)).sub(V3::splat(LAMP_CENTRE));
    let (e1, e2) = (V3::<L>::splat(LAMP_EDGE_1), V3::<L>::splat(LAMP_EDGE_2));
    let (a, b) = (q.dot(e1) / e1.dot(e1), q.dot(e2) / e2.dot(e2));
    hit.keep(within(a, -0.5, 0.5) & within(b, -0.5, 0.5), lamp, ID_LAMP);
    hit
}

/// [`closest`] one live lane at a time through the scalar code; dead lanes miss.
#[inline(always)]
fn closest_by_lane<L: Lanes>(o: V3<L>, d: V3<L>, live: L::M) -> Hit<L> {
    let mut lanes = [[0f32; MAX_LANES]; 7];
    for (buffer, value) in lanes.iter_mut().zip([
        o.x,
        o.y,
        o.z,
        d.x,
        d.y,
        d.z,
        L::select(live, L::splat(1.0), L::splat(0.0)),
    ]) {
        value.store(buffer);
    }
    let [ox, oy, oz, dx, dy, dz, on] = lanes;
    let mut t = [f32::INFINITY; MAX_LANES];
    let mut id = [ID_MISS; MAX_LANES];
    for i in (0..L::N).filter(|&i| on[i] != 0.0) {
        (t[i], id[i]) = closest_scalar([ox[i], oy[i], oz[i]], [dx[i], dy[i], dz[i]]);
    }
    Hit {
        t: L::load(&t),
        id: L::U::load(&id),
    }
}

#[inline(never)]
fn closest_scalar(o: [f32; 3], d: [f32; 3]) -> (f32, u32) {
    let hit = closest::<f32>(V3::splat(o), V3::splat(d));
    (hit.t, hit.id)
}

#[inline(always)]
fn hit<L: Lanes>(traversal: Traversal, o: V3<L>, d: V3<L>, live: L::M) -> Hit<L> {
    match traversal {
        Traversal::Lanes => closest(o, d),
        Traversal::ByLane => closest_by_lane(o, d, live),
    }
}

/// The two texels bracketing coordinate `c` along an axis (the texture repeats every 4 units)
/// and the second's weight.
#[inline(always)]
fn texel_axis<L: Lanes>(c: L) -> (L::U, L::U, L) {
    let c = c * L::splat(0.25);
    let x = (c - c.floor()) * L::splat(TEXELS as f32) - L::splat(0.5);
    let x0 = x.floor();
    let wrap = L::U::splat(TEXELS as u32 - 1);
    let i0 = (x0 + L::splat(TEXELS as f32)).to_u32() & wrap;
    (i0, i0.wrapping_add(L::U::splat(1)) & wrap, x - x0)
}

#[inline(always)]
fn texel<L: Lanes>(channel: &[f32], x: L::U, y: L::U) -> L {
    L::gather(
        channel,
        y.wrapping_mul(L::U::splat(TEXELS as u32)).wrapping_add(x),
    )
}

#[inline(always)]
fn checkerboard<L: Lanes>(scene: &Scene, u: L, v: L) -> V3<L> {
    let (x0, x1, fx) = texel_axis(u);
    let (y0, y1, fy) = texel_axis(v);
    let [r, g, b] = &scene.texture;
    V3 {
        x: bilinear(r, (x0, x1, fx), (y0, y1, fy)),
        y: bilinear(g, (x0, x1, fx), (y0, y1, fy)),
        z: bilinear(b, (x0, x1, fx), (y0, y1, fy)),
    }
}

#[inline(always)]
fn bilinear<L: Lanes>(
    channel: &[f32],
    (x0, x1, fx): (L::U, L::U, L),
    (y0, y1, fy): (L::U, L::U, L),
) -> L {
    let one = L::splat(1.0);
    let row0 = texel::<L>(channel, x0, y0) * (one - fx) + texel::<L>(channel, x1, y0) * fx;
    let row1 = texel::<L>(channel, x0, y1) * (one - fx) + texel::<L>(channel, x1, y1) * fx;
    row0 * (one - fy) + row1 * fy
}

/// Live lanes of `m`.
#[inline(always)]
fn count<L: Lanes>(m: L::M) -> u64 {
    let mut on = [0f32; MAX_LANES];
    L::select(m, L::splat(1.0), L::splat(0.0)).store(&mut on);
    on[..L::N].iter().map(|&x| x as u64).sum()
}

#[inline(always)]
fn to_world<L: Lanes>(scene: &Scene, a: V3<L>) -> V3<L> {
    V3::splat(scene.right)
        .scale(a.x)
        .add(V3::splat(scene.up).scale(a.y))
        .add(V3::splat(scene.forward).scale(a.z))
}

/// What a render counts besides its image.
#[derive(Default, Clone, Copy)]
pub struct Counts {
    /// Rays traced for live paths.
    pub rays: u64,
    /// Rays a packet's lanes traced or skipped: `rays`' share of it is the lanes' occupancy.
    pub lane_steps: u64,
}

/// Traces the `L::N` samples of pixel (`px`, `py`) from sample `first` on, adding their
/// radiance to `sum` in sample order.
#[inline(always)]
fn trace<L: Lanes>(
    scene: &Scene,
    traversal: Traversal,
    (px, py): (usize, usize),
    (first, spp): (usize, usize),
    counts: &mut Counts,
    sum: &mut [f32; 3],
) {
    let mut sampler = PacketSampler::<L>::new(px as u32, py as u32, first as u32, spp as u32, 0);
    let zero = L::splat(0.0);
    let one = L::splat(1.0);
    let inv_pi = L::splat(1.0 / PI);

    // Thin lens: aperture radius 0.1, focused at 5, 49.1 degrees across the shorter side.
    let tan_half_fov = L::splat(0.457_08);
    let aspect = scene.height as f32 / scene.width as f32;
    let ([film_x, film_y], [lens_u, lens_v]) = sampler.get_camera();
    let sx = (L::splat(px as f32) + film_x) * L::splat(2.0 / scene.width as f32) - one;
    let sy = (one - (L::splat(py as f32) + film_y) * L::splat(2.0 / scene.height as f32))
        * L::splat(aspect);
    let focus = L::splat(5.0);
    let on_focus = V3 {
        x: sx * tan_half_fov * focus,
        y: sy * tan_half_fov * focus,
        z: focus,
    };
    let r = lens_u.sqrt() * L::splat(0.1);
    let (sin, cos) = sin_cos(lens_v * L::splat(2.0 * PI));
    let lens = V3 {
        x: r * cos,
        y: r * sin,
        z: zero,
    };
    let mut o = V3::splat(scene.eye).add(to_world(scene, lens));
    let mut d = to_world(scene, on_focus.sub(lens).normalize());

    let mut throughput = V3::<L>::splat([1.0; 3]);
    let mut radiance = V3::<L>::splat([0.0; 3]);
    let mut live = L::mask(true);
    let mut bsdf_pdf = zero;
    let lamp_normal = V3::<L>::splat(LAMP_NORMAL);
    for depth in 0..=MAX_DEPTH {
        if !live.any() {
            break;
        }
        counts.rays += count::<L>(live);
        counts.lane_steps += L::N as u64;
        let h = hit(traversal, o, d, live);
        live = live & !h.id.equals(L::U::splat(ID_MISS));
        let on_lamp = h.id.equals(L::U::splat(ID_LAMP)) & live;
        if on_lamp.any() {
            let cos_lamp = zero - d.dot(lamp_normal);
            let front = zero.lt(cos_lamp) & on_lamp;
            let weight = if depth == 0 {
                one
            } else {
                let lamp_pdf = h.t * h.t / (cos_lamp * L::splat(LAMP_AREA));
                bsdf_pdf * bsdf_pdf / (bsdf_pdf * bsdf_pdf + lamp_pdf * lamp_pdf)
            };
            let seen = throughput.scale(L::splat(LAMP_RADIANCE) * weight);
            radiance = V3::select(front, radiance.add(seen), radiance);
        }
        live = live & !on_lamp;
        if depth == MAX_DEPTH {
            break;
        }

        let p = o.add(d.scale(h.t));
        let mut n = V3::<L>::splat([0.0, 0.0, 1.0]);
        let mut albedo = V3::<L>::splat([0.0; 3]);
        for (i, (centre, colour)) in SPHERES.iter().enumerate() {
            let m = h.id.equals(L::U::splat(i as u32));
            let sphere_normal = p.sub(V3::splat(*centre)).scale(L::splat(1.0 / RADIUS));
            n = V3::select(m, sphere_normal, n);
            albedo = V3::select(m, V3::splat(*colour), albedo);
        }
        let (is_floor, is_back, is_left) = (
            h.id.equals(L::U::splat(ID_FLOOR)),
            h.id.equals(L::U::splat(ID_BACK)),
            h.id.equals(L::U::splat(ID_LEFT)),
        );
        n = V3::select(is_back, V3::splat([0.0, -1.0, 0.0]), n);
        n = V3::select(is_left, V3::splat([1.0, 0.0, 0.0]), n);
        let textured = is_floor | is_back | is_left;
        if textured.any() {
            let u = L::select(is_left, p.y, p.x);
            let v = L::select(is_floor, p.y, p.z);
            albedo = V3::select(textured, checkerboard(scene, u, v), albedo);
        }
        n = V3::select(zero.lt(n.dot(d)), n.neg(), n);
        let u = sampler.get_vertex();
        let origin = p.add(n.scale(L::splat(EPSILON)));

        // A point on the lamp, weighed against the BSDF's density.
        let a = u.light[0] - L::splat(0.5);
        let b = u.light[1] - L::splat(0.5);
        let on_lamp = V3::splat(LAMP_CENTRE)
            .add(V3::splat(LAMP_EDGE_1).scale(a))
            .add(V3::splat(LAMP_EDGE_2).scale(b));
        let to_lamp = on_lamp.sub(origin);
        let dist2 = to_lamp.dot(to_lamp);
        let dist = dist2.sqrt();
        let wi = to_lamp.scale(one / dist);
        let cos_surface = n.dot(wi);
        let cos_lamp = zero - lamp_normal.dot(wi);
        let lit = live & zero.lt(cos_surface) & zero.lt(cos_lamp);
        if lit.any() {
            counts.rays += count::<L>(lit);
            counts.lane_steps += L::N as u64;
            let shadow = hit(traversal, origin, wi, lit);
            let seen = lit & !shadow.t.lt(dist * L::splat(0.999));
            let lamp_pdf = dist2 / (cos_lamp * L::splat(LAMP_AREA));
            let pdf = cos_surface * inv_pi;
            let weight = lamp_pdf * lamp_pdf / (lamp_pdf * lamp_pdf + pdf * pdf);
            let k = L::splat(LAMP_RADIANCE) * inv_pi * cos_surface / lamp_pdf * weight;
            radiance = V3::select(
                seen,
                radiance.add(throughput.mul(albedo).scale(k)),
                radiance,
            );
        }

        // A cosine-weighted continuation in the frame of Duff et al.
        let (sin, cos) = sin_cos(u.bsdf[1] * L::splat(2.0 * PI));
        let r = u.bsdf[0].sqrt();
        let z = (one - u.bsdf[0]).max(zero).sqrt();
        let sign = L::select(n.z.lt(zero), L::splat(-1.0), one);
        let a = L::splat(-1.0) / (sign + n.z);
        let b = n.x * n.y * a;
        let s = V3 {
            x: one + sign * n.x * n.x * a,
            y: sign * b,
            z: zero - sign * n.x,
        };
        let t = V3 {
            x: b,
            y: sign + n.y * n.y * a,
            z: zero - n.y,
        };
        d = s.scale(r * cos).add(t.scale(r * sin)).add(n.scale(z));
        bsdf_pdf = z * inv_pi;
        throughput = throughput.mul(albedo);
        live = live & zero.lt(z);
        if depth >= 2 {
            let q = throughput.x.max(throughput.y).max(throughput.z);
            let q = q.max(L::splat(0.05)).min(one);
            live = live & u.roulette.lt(q);
            throughput = throughput.scale(one / q);
        }
        o = origin;
    }
    let mut lanes = [[0f32; MAX_LANES]; 3];
    radiance.x.store(&mut lanes[0]);
    radiance.y.store(&mut lanes[1]);
    radiance.z.store(&mut lanes[2]);
    for i in 0..L::N {
        for (s, lane) in sum.iter_mut().zip(&lanes) {
            *s += lane[i];
        }
    }
}

/// Renders the image at `spp` samples per pixel (a multiple of `L::N`): mean radiance per
/// pixel, row-major.
#[inline(always)]
pub fn render<L: Lanes>(
    scene: &Scene,
    spp: usize,
    traversal: Traversal,
) -> (Vec<[f32; 3]>, Counts) {
    assert!(
        spp.is_multiple_of(L::N) && spp <= 256,
        "spp {spp} is not a multiple of {}",
        L::N
    );
    let mut image = vec![[0f32; 3]; scene.width * scene.height];
    let mut counts = Counts::default();
    for py in 0..scene.height {
        for px in 0..scene.width {
            let mut sum = [0f32; 3];
            for first in (0..spp).step_by(L::N) {
                trace::<L>(
                    scene,
                    traversal,
                    (px, py),
                    (first, spp),
                    &mut counts,
                    &mut sum,
                );
            }
            image[py * scene.width + px] = sum.map(|s| s / spp as f32);
        }
    }
    (image, counts)
}
