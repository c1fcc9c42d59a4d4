//! Area lights seen in flat mirrors: next-event estimation along a path that reflects once in
//! a planar mirror on its way to a lamp.
//!
//! Light a lamp throws onto a diffuse surface through a mirror (the caustic of a mirror block
//! in a Cornell box) reaches plain path tracing only when a BSDF-sampled ray happens to hit the
//! lamp after the mirror: rare for a small lamp, and then the path carries the lamp's whole
//! radiance, the fireflies such scenes are full of. In a flat mirror the lamp has an image, the
//! lamp reflected across the mirror's plane, and that image can be sampled like a lamp. From a
//! shading point x, sampling the image is sampling the real lamp from x', x reflected across
//! the plane (a reflection keeps distances and angles), so the lamp's own sampling routine and
//! density serve unchanged; the segment from x' to the sampled lamp point crosses the plane at
//! the mirror point m, and x -> m -> lamp is the path. The integrator checks it by tracing (m
//! must be the first surface x sees that way, a mirror of that plane, and the lamp must be in
//! view of m) and weighs it against the BSDF sample that could have made the same path, by the
//! power heuristic on both sides.
//!
//! Which mirrors: triangle meshes whose material is a plain `mirror` (no bump map or mix, which
//! would bend the reflection), grouped by plane; a plane takes part when it holds at least
//! [`MIN_PLANE_SHARE`] of the mirrors' area (a tessellated curved mirror has no such plane and
//! keeps plain path tracing), [`MAX_PLANES`] of them at most. Which lamps: the area lights
//! with some of their bounds on the side of the plane the shading point is on.
//!
//! Where a point sees an image, [`IMAGE_SHARE`] of its light samples go to the images and the
//! rest to the lights as before. An image is chosen by its lamp's power times its reach: the
//! share of the lamp's footprint on the plane (its bounding box projected from the point's
//! reflection) that the box around the plane's mirrors covers; a side face of a mirror block
//! shows a ceiling lamp to the floor, not to the ceiling. The choice may be any function of the
//! point (both sides of the MIS weight compute it alike, and a path an image cannot find keeps
//! its BSDF sample's full weight), so estimating it roughly costs noise, never bias. A scene
//! without such mirrors draws no extra random number and traces no extra ray, and renders the
//! same bytes as without this file.

use glam::{Vec2, Vec3};

use super::area::AreaLight;
use crate::geometry::{SceneGeometry, ShapeSurface, SurfaceHit};
use crate::math::Frame;

/// The share of a shading point's light samples that go to lamp images when it sees one.
pub const IMAGE_SHARE: f32 = 0.5;
/// Mirror planes kept at most (each shading point looks at every one).
pub const MAX_PLANES: usize = 16;
/// Distinct planes the grouping follows before it stops adding new ones (a curved mirror's
/// facets would otherwise make a plane each).
const MAX_CANDIDATE_PLANES: usize = 64;
/// The least share of the mirrors' area a plane must hold to take part.
pub const MIN_PLANE_SHARE: f32 = 0.05;
/// (plane, side, lamp) images kept at most: the heaviest by lamp power.
const MAX_IMAGES: usize = 32;
/// Unit normals closer than this (cosine) are the same plane's.
const PARALLEL: f32 = 1.0 - 1e-5;
/// Plane offsets and sides are told apart to this fraction of the scene's size.
const RELATIVE_TOLERANCE: f32 = 1e-5;
/// How closely a mirror's sampled reflection must follow the plane's (cosine): shading normals
/// that tilt the reflection more than this make the mirror's point useless to the images, on
/// the light-sampling side and the BSDF side alike.
const SAME_REFLECTION: f32 = 1.0 - 1e-4;

/// A mirror plane: the points p with `n . p = d`; its front is where `n . p > d`.
#[derive(Clone, Copy, Debug)]
struct MirrorPlane {
    n: Vec3,
    d: f32,
    area: f32,
    /// Axes in the plane, and the box (along them) around the plane's mirrors.
    frame: Frame,
    window_lo: Vec2,
    window_hi: Vec2,
}

impl MirrorPlane {
    /// Which side of the plane `p` is on (true: the front); None within `tolerance` of it.
    fn side(&self, p: Vec3, tolerance: f32) -> Option<bool> {
        let s = self.n.dot(p) - self.d;
        if s > tolerance {
            Some(true)
        } else if s < -tolerance {
            Some(false)
        } else {
            None
        }
    }

    fn reflect_point(&self, p: Vec3) -> Vec3 {
        p - 2.0 * (self.n.dot(p) - self.d) * self.n
    }

    fn reflect_dir(&self, v: Vec3) -> Vec3 {
        v - 2.0 * self.n.dot(v) * self.n
    }

    /// A point's coordinates along the plane's axes.
    fn in_plane(&self, p: Vec3) -> Vec2 {
        Vec2::new(self.frame.s.dot(p), self.frame.t.dot(p))
    }
}

/// A lamp's image in one side of a plane.
#[derive(Clone, Copy, Debug)]
struct Image {
    plane: u16,
    /// Seen from the plane's front (else from its back).
    front: bool,
    /// Index into `Lights::lights` (an area light).
    light: u32,
    /// The lamp's selection probability among all lights (images are chosen by lamp power
    /// times reach).
    weight: f32,
    /// The corners of the lamp's bounding box on this side: coordinates along the plane's
    /// axes, and height above it (first `corner_count` entries).
    corners: [Vec3; 8],
    corner_count: u8,
    /// The box around where the lamp's bounding box crosses the plane (empty when it does not).
    cut_lo: Vec2,
    cut_hi: Vec2,
}

impl Image {
    /// The image of the lamp inside `lo..hi` on side `front` of `plane`; None when no part of
    /// the box is on that side.
    fn new(plane: &MirrorPlane, front: bool, lo: Vec3, hi: Vec3, tolerance: f32) -> Option<Self> {
        let corner = |c: u32| {
            Vec3::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let height = |c: Vec3| plane.n.dot(c) - plane.d;
        let mut image = Image {
            plane: 0,
            front,
            light: 0,
            weight: 0.0,
            corners: [Vec3::ZERO; 8],
            corner_count: 0,
            cut_lo: Vec2::INFINITY,
            cut_hi: Vec2::NEG_INFINITY,
        };
        for c in 0..8 {
            let a = corner(c);
            let ha = height(a);
            let q = plane.in_plane(a).extend(ha);
            if plane.side(a, tolerance) == Some(front)
                && !image.corners[..image.corner_count as usize].contains(&q)
            {
                image.corners[image.corner_count as usize] = q;
                image.corner_count += 1;
            }
            for axis in 0..3 {
                let bit = 1 << axis;
                if c & bit == 0 {
                    let b = corner(c | bit);
                    let hb = height(b);
                    if ha * hb < 0.0 {
                        let cut = plane.in_plane(a + (b - a) * (ha / (ha - hb)));
                        image.cut_lo = image.cut_lo.min(cut);
                        image.cut_hi = image.cut_hi.max(cut);
                    }
                }
            }
        }
        (image.corner_count > 0).then_some(image)
    }

    /// The share of the lamp's footprint on the plane that the box around the plane's mirrors
    /// covers, seen from `p` (on the image's side): the lamp's part on that side, its box's
    /// corners projected onto the plane from p's reflection together with where the box
    /// crosses the plane. About the share of the image's samples from `p` that meet a mirror.
    fn reach(&self, plane: &MirrorPlane, p: Vec3, tolerance: f32) -> f32 {
        let p_height = plane.n.dot(p) - plane.d;
        let p_uv = plane.in_plane(p);
        let (mut lo, mut hi) = (self.cut_lo, self.cut_hi);
        for c in &self.corners[..self.corner_count as usize] {
            // From p's reflection (height -p_height) through the corner (height c.z).
            let q = p_uv + (c.truncate() - p_uv) * (p_height / (p_height + c.z));
            lo = lo.min(q);
            hi = hi.max(q);
        }
        let (lo, hi) = (lo - tolerance, hi + tolerance);
        let footprint = (hi - lo).max(Vec2::ZERO);
        let overlap = (hi.min(plane.window_hi) - lo.max(plane.window_lo)).max(Vec2::ZERO);
        let share = overlap.x * overlap.y / (footprint.x * footprint.y);
        if share.is_finite() {
            share.clamp(0.0, 1.0)
        } else {
            0.0
        }
    }
}

/// The lamp images of a scene's flat mirrors (none in most scenes).
#[derive(Default)]
pub struct MirrorImages {
    planes: Vec<MirrorPlane>,
    images: Vec<Image>,
    /// Shapes that are flat mirrors, sorted.
    mirror_shapes: Vec<u32>,
    tolerance: f32,
}

/// How likely each lamp image is to be chosen from one shading point: what
/// [`super::Lights::sample_image`] draws from.
pub struct ImageWeights {
    p: Vec3,
    weights: [f32; MAX_IMAGES],
    total: f32,
}

/// A light sample through a mirror, as seen from the shading point.
#[derive(Clone, Copy, Debug)]
pub struct ImageSample {
    /// Unit direction from the shading point to the mirror point.
    pub wi: Vec3,
    /// Distance from the shading point to the mirror point.
    pub to_mirror: f32,
    /// Unit direction from the mirror point to the lamp point.
    pub reflected: Vec3,
    /// The sampled point on the lamp.
    pub light_point: Vec3,
    /// Radiance the lamp point sends towards the mirror.
    pub li: Vec3,
    /// Solid-angle density at the shading point, including the image's choice (not
    /// [`IMAGE_SHARE`]).
    pub pdf: f32,
    /// The mirror plane (what [`super::Lights::mirror_plane`] says of the mirror point).
    pub plane: u16,
    /// The lamp's index among the lights.
    pub lamp: u32,
}

/// Whether a mirror's sampled reflection `wi` is the plane reflection `expected` (both unit).
pub fn follows_plane(wi: Vec3, expected: Vec3) -> bool {
    wi.dot(expected) >= SAME_REFLECTION
}

impl MirrorImages {
    /// Sides of every plane as seen from `p` (None beyond the planes).
    fn sides(&self, p: Vec3) -> [Option<bool>; MAX_PLANES] {
        let mut sides = [None; MAX_PLANES];
        for (side, plane) in sides.iter_mut().zip(&self.planes) {
            *side = plane.side(p, self.tolerance);
        }
        sides
    }

    /// How likely each image is to be chosen from `p` (unnormalised, 0 for the ones it does
    /// not see), and their sum.
    fn weights(&self, p: Vec3) -> ([f32; MAX_IMAGES], f32) {
        let sides = self.sides(p);
        let mut weights = [0.0; MAX_IMAGES];
        let mut total = 0.0;
        for (w, image) in weights.iter_mut().zip(&self.images) {
            let plane = &self.planes[image.plane as usize];
            if sides[image.plane as usize] == Some(image.front) {
                *w = image.weight * image.reach(plane, p, self.tolerance);
                total += *w;
            }
        }
        (weights, total)
    }

    /// The lamp images of the flat mirrors among `mirror_shapes` (shapes whose material is a
    /// plain `mirror`; see the module doc for which take part) of the area lights `lamps`: each
    /// its index among the scene's lights, the light, and its selection probability.
    pub fn new(
        mirror_shapes: &[u32],
        geometry: &SceneGeometry,
        lamps: &[(u32, &AreaLight, f32)],
    ) -> Self {
        let scale = geometry
            .bounds()
            .map_or(1.0, |(lo, hi)| (hi - lo).length().max(1e-3));
        let tolerance = RELATIVE_TOLERANCE * scale;
        let mut candidates: Vec<MirrorPlane> = Vec::new();
        let mut total_area = 0.0f64;
        let mut shapes: Vec<u32> = mirror_shapes.to_vec();
        shapes.sort_unstable();
        shapes.dedup();
        for &shape in &shapes {
            let Some(ShapeSurface::Triangles(triangles)) = geometry.shape_surface(shape) else {
                continue;
            };
            for triangle in &triangles {
                let area = triangle.area();
                let n = triangle.n.normalize_or_zero();
                if area.is_nan() || area <= 0.0 || n == Vec3::ZERO {
                    continue;
                }
                total_area += f64::from(area);
                // One orientation per plane: its largest component positive.
                let n = if n[n.abs().max_position()] < 0.0 {
                    -n
                } else {
                    n
                };
                let d = n.dot(triangle.vertices[0]);
                let same = candidates
                    .iter()
                    .position(|p| p.n.dot(n) >= PARALLEL && (p.d - d).abs() <= tolerance);
                let plane = match same {
                    Some(i) => &mut candidates[i],
                    None if candidates.len() < MAX_CANDIDATE_PLANES => {
                        candidates.push(MirrorPlane {
                            n,
                            d,
                            area: 0.0,
                            frame: Frame::from_normal(n),
                            window_lo: Vec2::INFINITY,
                            window_hi: Vec2::NEG_INFINITY,
                        });
                        candidates.last_mut().expect("just pushed")
                    }
                    None => continue,
                };
                plane.area += area;
                for v in triangle.vertices {
                    let q = plane.in_plane(v);
                    plane.window_lo = plane.window_lo.min(q);
                    plane.window_hi = plane.window_hi.max(q);
                }
            }
        }
        let least = MIN_PLANE_SHARE * total_area as f32;
        candidates.retain(|p| p.area >= least && p.area > 0.0);
        candidates.sort_by(|a, b| b.area.total_cmp(&a.area));
        candidates.truncate(MAX_PLANES);

        // The heaviest lamps only: no more can have an image among the heaviest images.
        let mut lamps = lamps.to_vec();
        lamps.sort_by(|a, b| b.2.total_cmp(&a.2));
        lamps.truncate(MAX_IMAGES);
        let mut images = Vec::new();
        for (index, plane) in candidates.iter().enumerate() {
            for &(light, lamp, weight) in &lamps {
                let (lo, hi) = lamp.bounds();
                for front in [true, false] {
                    if let Some(image) = Image::new(plane, front, lo, hi, tolerance) {
                        images.push(Image {
                            plane: index as u16,
                            light,
                            weight,
                            ..image
                        });
                    }
                }
            }
        }
        images.sort_by(|a, b| b.weight.total_cmp(&a.weight));
        images.truncate(MAX_IMAGES);
        images.retain(|i| i.weight > 0.0);
        if images.is_empty() {
            return Self::default();
        }
        Self {
            planes: candidates,
            images,
            mirror_shapes: shapes,
            tolerance,
        }
    }

    /// Whether there are no images (most scenes have none).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }

    /// The lamp images a shading point `p` sees, weighted; None where it sees none (its light
    /// samples then all go to the lights, else [`IMAGE_SHARE`] of them to these).
    pub fn seen_from(&self, p: Vec3) -> Option<ImageWeights> {
        let (weights, total) = self.weights(p);
        (total > 0.0).then_some(ImageWeights { p, weights, total })
    }

    /// Samples a lamp image seen from the point `seen` was weighed at: `u_select` chooses the
    /// image, `u` the point on the lamp (`lamp` gives the area light of a light index). None
    /// when the chosen image shows nothing from there.
    pub fn sample<'a>(
        &self,
        seen: &ImageWeights,
        u_select: f32,
        u: Vec2,
        lamp: impl Fn(u32) -> Option<&'a AreaLight>,
    ) -> Option<ImageSample> {
        let ImageWeights { p, weights, total } = seen;
        let target = u_select * total;
        let mut sum = 0.0;
        let mut chosen = None;
        for (&w, image) in weights.iter().zip(&self.images) {
            if w > 0.0 {
                chosen = Some((w, image));
                sum += w;
                if target < sum {
                    break;
                }
            }
        }
        let (weight, image) = chosen?;
        let plane = &self.planes[image.plane as usize];
        let light = lamp(image.light)?;
        let from = plane.reflect_point(*p);
        let s = light.sample(from, u)?;
        // Where the segment from p's image to the lamp point crosses the plane.
        let to_mirror = (plane.d - plane.n.dot(from)) / plane.n.dot(s.wi);
        if !(to_mirror > 0.0 && to_mirror < s.dist) {
            return None;
        }
        Some(ImageSample {
            wi: plane.reflect_dir(s.wi),
            to_mirror,
            reflected: s.wi,
            light_point: from + s.wi * s.dist,
            li: s.li,
            pdf: weight / total * s.pdf,
            plane: image.plane,
            lamp: image.light,
        })
    }

    /// Solid-angle density with which [`Self::sample`] from `p` would have chosen the point
    /// `hit` on lamp `light` (light index `index`) through mirror plane `plane` (for MIS when a
    /// BSDF-sampled ray reaches a lamp after that mirror; not including [`IMAGE_SHARE`]).
    pub fn pdf(
        &self,
        p: Vec3,
        plane: u16,
        (index, light): (u32, &AreaLight),
        hit: &SurfaceHit,
    ) -> f32 {
        let (weights, total) = self.weights(p);
        let Some(weight) = weights
            .iter()
            .zip(&self.images)
            .find(|(&w, i)| w > 0.0 && i.plane == plane && i.light == index)
            .map(|(&w, _)| w)
        else {
            return 0.0;
        };
        let from = self.planes[plane as usize].reflect_point(p);
        weight / total * light.pdf(from, hit.p, hit.ng)
    }

    /// The mirror plane a hit lies in, when it is on a flat mirror that takes part.
    pub fn mirror_plane(&self, hit: &SurfaceHit) -> Option<u16> {
        self.mirror_shapes.binary_search(&hit.shape).ok()?;
        self.planes
            .iter()
            .position(|plane| {
                plane.n.dot(hit.ng).abs() >= PARALLEL
                    && (plane.n.dot(hit.p) - plane.d).abs() <= self.tolerance
            })
            .map(|i| i as u16)
    }

    /// The plane reflection of direction `v` in mirror plane `plane`.
    pub fn reflect(&self, plane: u16, v: Vec3) -> Vec3 {
        self.planes[plane as usize].reflect_dir(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plane x = 1 (its front, where the normal +x points, is beyond the room), with a
    /// mirror over y in [-1, 1], z in [0, 2].
    fn wall() -> MirrorPlane {
        let n = Vec3::X;
        let mut plane = MirrorPlane {
            n,
            d: 1.0,
            area: 4.0,
            frame: Frame::from_normal(n),
            window_lo: Vec2::INFINITY,
            window_hi: Vec2::NEG_INFINITY,
        };
        for corner in [
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 2.0),
            Vec3::new(1.0, -1.0, 2.0),
            Vec3::new(1.0, 1.0, 0.0),
        ] {
            let q = plane.in_plane(corner);
            plane.window_lo = plane.window_lo.min(q);
            plane.window_hi = plane.window_hi.max(q);
        }
        plane
    }

    #[test]
    fn reach_is_the_share_of_the_lamps_footprint_the_mirror_covers() {
        let plane = wall();
        // A small lamp at height 1.5 in the room, in front of the mirror's middle.
        let (lo, hi) = (Vec3::new(0.4, -0.1, 1.5), Vec3::new(0.6, 0.1, 1.5));
        let image = Image::new(&plane, false, lo, hi, 1e-5).expect("the lamp is in the room");
        assert!(
            Image::new(&plane, true, lo, hi, 1e-5).is_none(),
            "nothing behind the wall"
        );
        // From the floor the lamp's image lies inside the mirror: all of it.
        let floor = image.reach(&plane, Vec3::new(0.0, 0.0, 0.0), 1e-5);
        assert!((floor - 1.0).abs() < 1e-6, "{floor}");
        // From high above, the line to the image meets the plane above the mirror's top.
        assert_eq!(image.reach(&plane, Vec3::new(0.5, 0.0, 10.0), 1e-5), 0.0);
        // From higher up, the footprint straddles the mirror's top edge (z = 2): the line from
        // p's reflection (2, 0, 3) to a lamp point (x, 0, 1.5) meets the plane at height
        // 3 - 1.5 / (2 - x), 1.93 for the lamp's near edge and 2.06 for its far edge.
        let p = Vec3::new(0.0, 0.0, 3.0);
        assert_eq!(plane.reflect_point(p), Vec3::new(2.0, 0.0, 3.0));
        let z = |x: f32| 3.0 - 1.5 / (2.0 - x);
        let expected = (2.0 - z(0.6)) / (z(0.4) - z(0.6));
        let half = image.reach(&plane, p, 1e-5);
        assert!((half - expected).abs() < 1e-3, "{half} against {expected}");
        assert!(half > 0.0 && half < 1.0);
    }
}
