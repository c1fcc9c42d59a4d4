//! World-space geometry and ray queries: every shape of the scene (triangles and analytic
//! shapes) in one BVH.
//!
//! obvhs builds a CWBVH8 over primitive bounding boxes: each triangle of every mesh and each
//! sphere, disk and cylinder is one primitive (`build_cwbvh` over AABBs is what
//! `build_cwbvh_from_tris` does when spatial splits are off, as in `medium_build`). Primitive
//! data is stored in BVH leaf order for locality. `wide_bvh` converts the CWBVH into its own
//! SIMD layout and traces it. The infinite planes have no bounding box and are tested
//! separately.

mod analytic;
mod footprint;
mod hit;
mod plane;
mod simd;
mod triangle;
mod wide_bvh;
mod wide_node;
mod world_range;

#[cfg(test)]
pub(crate) mod tests;

use std::time::{Duration, Instant};

use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::BvhBuildParams;

use crate::math::Ray;
use crate::shape::{Placement, ShapeDesc};

pub use analytic::AnalyticShape;
pub use footprint::placed_bytes;
pub use hit::{PrimHit, SurfaceHit, SurfaceSample};
pub use simd::Isa;
pub use triangle::TriangleSurface;
pub use world_range::MAX_WORLD_COORD;

use plane::InfinitePlane;
use triangle::{TriangleEdges, WorldMesh};
use wide_bvh::WideBvh;
use world_range::within_world;

/// A BVH primitive: what the traversal reads, and where its shading data lives.
#[derive(Clone, Copy, Debug)]
enum Prim {
    Triangle {
        edges: TriangleEdges,
        /// Index into `SceneGeometry::meshes`, and the triangle within that mesh.
        mesh: u32,
        tri: u32,
    },
    /// Index into `SceneGeometry::analytic`.
    Analytic(u32),
}

// One cache line per primitive: the indices fit in the padding the 16-byte aligned edges leave.
const _: () = assert!(std::mem::size_of::<Prim>() == 64);

/// The surface of one shape, owned, for sampling points on emitters.
#[derive(Clone, Debug)]
pub enum ShapeSurface {
    Triangles(Vec<TriangleSurface>),
    Analytic(Box<AnalyticShape>),
}

pub struct SceneGeometry {
    bvh: WideBvh,
    /// BVH primitives in leaf order. `SurfaceHit::prim` is the leaf-order index, or
    /// `prims.len()` + the index of a plane.
    prims: Vec<Prim>,
    meshes: Vec<WorldMesh>,
    analytic: Vec<AnalyticShape>,
    planes: Vec<InfinitePlane>,
    triangle_count: usize,
    /// Bounds of everything but the planes (invalid when there is nothing).
    bounds: Aabb,
    build_time: Duration,
    /// Per shape, whether [`Self::occluded`] looks through it (empty: through none).
    crossed: Vec<bool>,
}

impl SceneGeometry {
    /// The scene's shapes, indexed as given (hits report that index).
    pub fn build(shapes: &[ShapeDesc]) -> Self {
        let start = Instant::now();
        let mut meshes = Vec::new();
        let mut analytic = Vec::new();
        let mut planes = Vec::new();
        // One of each per primitive: reserved, so that they never hold spare capacity.
        let primitives: u64 = shapes.iter().map(|s| s.geometry.primitive_count()).sum();
        let mut aabbs = Vec::with_capacity(primitives as usize);
        let mut prims = Vec::with_capacity(primitives as usize);
        for (index, shape) in shapes.iter().enumerate() {
            let index = index as u32;
            let m = &shape.object_to_world;
            let ro = shape.reverse_orientation;
            match shape.geometry.placement() {
                Placement::Triangles(mesh) => {
                    let (world, issues) = WorldMesh::new(index, mesh, m, ro);
                    if issues.bad_triangles > 0 || issues.dropped_normals || issues.dropped_uvs {
                        tracing::warn!(
                            "shape \"{}\": {} triangles skipped (index out of range, zero \
                             area, or beyond {MAX_WORLD_COORD:e} in world space), normals \
                             dropped: {}, uvs dropped: {}",
                            shape.name,
                            issues.bad_triangles,
                            issues.dropped_normals,
                            issues.dropped_uvs
                        );
                    }
                    let mesh_index = meshes.len() as u32;
                    for tri in 0..world.triangle_count() as u32 {
                        let vertices = world.vertices(tri);
                        aabbs.push(Aabb::from_points(&vertices.map(Vec3A::from)));
                        prims.push(Prim::Triangle {
                            edges: TriangleEdges::new(vertices),
                            mesh: mesh_index,
                            tri,
                        });
                    }
                    meshes.push(world);
                }
                Placement::Unbounded(normal) => match InfinitePlane::new(index, normal, m, ro) {
                    Some(plane) => planes.push(plane),
                    None => tracing::warn!("shape \"{}\": degenerate plane skipped", shape.name),
                },
                Placement::Exact(surface) => match surface
                    .and_then(|s| AnalyticShape::new(index, s, m, ro))
                {
                    Some(s)
                        if !s.world_bounds().valid()
                            || !within_world(s.world_bounds().min.into())
                            || !within_world(s.world_bounds().max.into()) =>
                    {
                        tracing::warn!(
                            "shape \"{}\": skipped, it reaches beyond {MAX_WORLD_COORD:e} in \
                             world space",
                            shape.name
                        )
                    }
                    Some(s) => {
                        let a = analytic.len() as u32;
                        aabbs.push(s.world_bounds());
                        prims.push(Prim::Analytic(a));
                        analytic.push(s);
                    }
                    None => tracing::warn!("shape \"{}\": degenerate shape skipped", shape.name),
                },
            }
        }

        let bounds = aabbs.iter().fold(Aabb::INVALID, |b, a| b.union(a));
        let (bvh, prims) = if aabbs.is_empty() {
            (WideBvh::default(), Vec::new())
        } else {
            let mut core_time = Duration::ZERO;
            // obvhs's slow preset (pre-splitting, wider PLOC search, more reinsertion): its
            // faster traversal pays back its longer build within seconds of rendering at 1080p
            // (bench/RESULTS.md, "Figures moved out of the code").
            let cwbvh = build_cwbvh(&aabbs, BvhBuildParams::slow_build(), &mut core_time);
            let order = &cwbvh.primitive_indices;
            let prims: Vec<Prim> = order.iter().map(|&i| prims[i as usize]).collect();
            let boxes: Vec<Aabb> = order.iter().map(|&i| aabbs[i as usize]).collect();
            let triangles: Vec<Option<TriangleEdges>> = prims
                .iter()
                .map(|p| match *p {
                    Prim::Triangle { edges, .. } => Some(edges),
                    Prim::Analytic(_) => None,
                })
                .collect();
            (WideBvh::new(&cwbvh, &boxes, &triangles), prims)
        };
        let triangle_count = meshes.iter().map(WorldMesh::triangle_count).sum();
        Self {
            bvh,
            prims,
            meshes,
            analytic,
            planes,
            triangle_count,
            bounds,
            build_time: start.elapsed(),
            crossed: Vec::new(),
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Wall time of [`Self::build`] (world transform, bounding boxes and BVH).
    pub fn build_time(&self) -> Duration {
        self.build_time
    }

    /// World bounds (min, max) of all finite geometry; None when there is none.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.bounds
            .valid()
            .then(|| (self.bounds.min.into(), self.bounds.max.into()))
    }

    /// Runs ray queries on `isa` from now on (all give the same results; tests and benches
    /// compare them); false when this CPU lacks it.
    pub fn set_isa(&mut self, isa: Isa) -> bool {
        self.bvh.set_isa(isa)
    }

    /// Closest hit with t in (0, tmax), with everything shading needs.
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Option<SurfaceHit> {
        self.surface(ray, &self.closest(ray, tmax)?)
    }

    /// The closest primitive with t in (0, tmax): the traversal alone. Equal distances within
    /// the BVH go to the lowest primitive index; a plane (tested first) keeps a tie with it.
    pub fn closest(&self, ray: &Ray, tmax: f32) -> Option<PrimHit> {
        if !(ray.origin.is_finite() && ray.dir.is_finite()) || tmax.is_nan() {
            return None;
        }
        let (origin, dir) = (Vec3A::from(ray.origin), canonical_dir(ray.dir));
        let mut closest = None;
        let mut t_closest = tmax;
        for (i, plane) in self.planes.iter().enumerate() {
            if let Some(t) = plane.intersect(origin, dir, t_closest) {
                t_closest = t;
                closest = Some(PrimHit {
                    prim: (self.prims.len() + i) as u32,
                    t,
                    b1: 0.0,
                    b2: 0.0,
                });
            }
        }
        let hit = self.bvh.closest(origin, dir, t_closest, |slot, bound| {
            match self.prims[slot as usize] {
                Prim::Analytic(a) => self.analytic[a as usize].intersect(origin, dir, bound),
                Prim::Triangle { .. } => None,
            }
        });
        hit.or(closest)
    }

    /// The surface data of `hit`, which [`Self::closest`] returned for `ray`.
    pub fn surface(&self, ray: &Ray, hit: &PrimHit) -> Option<SurfaceHit> {
        let (origin, dir) = (Vec3A::from(ray.origin), canonical_dir(ray.dir));
        match self.prims.get(hit.prim as usize) {
            Some(&Prim::Triangle { edges, mesh, tri }) => {
                Some(self.meshes[mesh as usize].hit(tri, &edges, hit.t, hit.b1, hit.b2, hit.prim))
            }
            Some(&Prim::Analytic(a)) => {
                // The details of the accepted root, computed as the traversal's test did.
                Some(self.analytic[a as usize].hit(origin, dir, hit.t, hit.prim))
            }
            None => {
                let plane = self.planes.get(hit.prim as usize - self.prims.len())?;
                Some(plane.hit(origin, dir, hit.t, hit.prim))
            }
        }
    }

    /// Makes [`Self::occluded`] look through the shapes `crossed` names (by index; `null`
    /// surfaces, which paths cross too). Closest hits still find them.
    pub fn cross_in_occlusion(&mut self, crossed: Vec<bool>) {
        let prims = &self.prims;
        let meshes = &self.meshes;
        self.bvh
            .cross_in_any_hit(|slot| match prims.get(slot as usize) {
                Some(Prim::Triangle { mesh, .. }) => crossed
                    .get(meshes[*mesh as usize].shape as usize)
                    .copied()
                    .unwrap_or(false),
                _ => false,
            });
        self.crossed = crossed;
    }

    fn is_crossed(&self, shape: u32) -> bool {
        self.crossed.get(shape as usize).copied().unwrap_or(false)
    }

    /// Whether some shape is an infinite plane, which reaches beyond [`Self::bounds`].
    pub fn has_planes(&self) -> bool {
        !self.planes.is_empty()
    }

    /// Whether anything blocks the ray within (0, tmax), but the shapes
    /// [`Self::cross_in_occlusion`] named.
    pub fn occluded(&self, ray: &Ray, tmax: f32) -> bool {
        if !(ray.origin.is_finite() && ray.dir.is_finite()) || tmax.is_nan() {
            return false;
        }
        let (origin, dir) = (Vec3A::from(ray.origin), canonical_dir(ray.dir));
        if self.planes.iter().any(|plane| {
            !self.is_crossed(plane.shape) && plane.intersect(origin, dir, tmax).is_some()
        }) {
            return true;
        }
        self.bvh.any(origin, dir, tmax, |slot, tmax| {
            match self.prims[slot as usize] {
                Prim::Analytic(a) => {
                    let shape = &self.analytic[a as usize];
                    !self.is_crossed(shape.shape) && shape.intersect(origin, dir, tmax).is_some()
                }
                Prim::Triangle { .. } => false,
            }
        })
    }

    /// The surface of shape `shape` for light sampling; None for planes (infinite), shapes
    /// skipped as degenerate, and indices without a shape.
    pub fn shape_surface(&self, shape: u32) -> Option<ShapeSurface> {
        if let Some(a) = self.analytic.iter().find(|a| a.shape == shape) {
            return Some(ShapeSurface::Analytic(Box::new(a.clone())));
        }
        let mesh = self.meshes.iter().find(|m| m.shape == shape)?;
        let triangles: Vec<TriangleSurface> = (0..mesh.triangle_count() as u32)
            .map(|tri| mesh.surface(tri))
            .collect();
        (!triangles.is_empty()).then_some(ShapeSurface::Triangles(triangles))
    }
}

/// The world-space triangles of a shape that is not part of the scene's geometry (a portal):
/// a mesh's (its valid ones, front sides as a shape's), an exact shape's tessellation in
/// `segments`, none for an infinite plane.
pub(crate) fn world_triangles(
    geometry: &crate::shape::Geometry,
    object_to_world: &glam::Mat4,
    reverse_orientation: bool,
    segments: u32,
) -> Vec<TriangleSurface> {
    let tessellated;
    let mesh = match geometry.placement() {
        Placement::Triangles(mesh) => mesh,
        Placement::Exact(_) => match geometry.tessellate(segments) {
            Some(mesh) => {
                tessellated = mesh;
                &tessellated
            }
            None => return Vec::new(),
        },
        Placement::Unbounded(_) => return Vec::new(),
    };
    let (world, _) = triangle::WorldMesh::new(0, mesh, object_to_world, reverse_orientation);
    (0..world.triangle_count() as u32)
        .map(|tri| world.surface(tri))
        .collect()
}

/// The ray direction with -0.0 components turned into +0.0, so that a zero component has one
/// sign whatever produced it (the slab test picks near and far planes by the sign).
#[inline(always)]
fn canonical_dir(dir: Vec3) -> Vec3A {
    Vec3A::from(dir) + Vec3A::ZERO
}
