//! World-space geometry and ray queries: every shape of the scene (triangles and analytic
//! shapes) in one obvhs BVH.
//!
//! The BVH is one obvhs CWBVH8 built over primitive bounding boxes: each triangle of every mesh
//! and each sphere, disk and cylinder is one primitive (`build_cwbvh` over AABBs is what
//! `build_cwbvh_from_tris` does when spatial splits are off, as in `medium_build`). Primitive
//! data is stored in BVH leaf order for locality. The infinite planes have no bounding box and
//! are tested separately.

mod analytic;
mod hit;
mod plane;
mod triangle;
mod world_range;

#[cfg(test)]
pub(crate) mod tests;

use std::time::{Duration, Instant};

use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::RayHit;
use obvhs::BvhBuildParams;

use crate::math::Ray;
use crate::shape::Geometry;
use crate::shape::ShapeDesc;

pub use analytic::AnalyticShape;
pub use hit::{SurfaceHit, SurfaceSample};
pub use triangle::TriangleSurface;
pub use world_range::MAX_WORLD_COORD;

use analytic::QuadricHit;
use plane::InfinitePlane;
use triangle::{TriangleEdges, WorldMesh};
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
    bvh: CwBvh,
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
}

/// The closest primitive found so far during a traversal.
#[derive(Clone, Copy)]
enum Closest {
    None,
    Triangle {
        slot: u32,
        edges: TriangleEdges,
        mesh: u32,
        tri: u32,
        b1: f32,
        b2: f32,
    },
    Analytic {
        slot: u32,
        shape: u32,
        hit: QuadricHit,
    },
    Plane(u32),
}

impl SceneGeometry {
    /// The scene's shapes, indexed as given (hits report that index).
    pub fn build(shapes: &[ShapeDesc]) -> Self {
        let start = Instant::now();
        let mut meshes = Vec::new();
        let mut analytic = Vec::new();
        let mut planes = Vec::new();
        let mut aabbs = Vec::new();
        let mut prims = Vec::new();
        for (index, shape) in shapes.iter().enumerate() {
            let index = index as u32;
            let m = &shape.object_to_world;
            let ro = shape.reverse_orientation;
            match &shape.geometry {
                Geometry::Mesh(mesh) => {
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
                Geometry::Plane { normal } => match InfinitePlane::new(index, *normal, m, ro) {
                    Some(plane) => planes.push(plane),
                    None => tracing::warn!("shape \"{}\": degenerate plane skipped", shape.name),
                },
                quadric => match AnalyticShape::new(index, quadric, m, ro) {
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
        let bvh = if aabbs.is_empty() {
            CwBvh::default()
        } else {
            let mut core_time = Duration::ZERO;
            // obvhs's slow preset (pre-splitting, wider PLOC search, more reinsertion) traces
            // CaptainFalcon 13% faster and the 2M-triangle heavy scene 10% faster than the
            // medium one, for +1.5 us of build per triangle on 2 cores (heavy: 2.3 -> 5.4 s):
            // paid back within seconds of rendering at 1080p.
            build_cwbvh(&aabbs, BvhBuildParams::slow_build(), &mut core_time)
        };
        let prims = bvh
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize])
            .collect();
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

    /// Closest hit with t in (0, tmax).
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Option<SurfaceHit> {
        if !(ray.origin.is_finite() && ray.dir.is_finite()) || tmax.is_nan() {
            return None;
        }
        let (origin, dir) = (Vec3A::from(ray.origin), canonical_dir(ray.dir));
        let mut closest = Closest::None;
        let mut t_closest = tmax;
        for (i, plane) in self.planes.iter().enumerate() {
            if let Some(t) = plane.intersect(origin, dir, t_closest) {
                t_closest = t;
                closest = Closest::Plane(i as u32);
            }
        }

        let bvh_ray = obvhs::ray::Ray::new(origin, dir, 0.0, t_closest);
        let mut bvh_hit = RayHit::none();
        // The traversal accepts exactly the t values below its current tmax, and every test
        // below only returns such values, so recording the details here is recording the
        // accepted hit.
        self.bvh.ray_traverse(bvh_ray, &mut bvh_hit, |r, slot| {
            match self.prims[slot] {
                Prim::Triangle { edges, mesh, tri } => {
                    if let Some((t, b1, b2)) = edges.intersect(r.origin, r.direction, r.tmax) {
                        closest = Closest::Triangle {
                            slot: slot as u32,
                            edges,
                            mesh,
                            tri,
                            b1,
                            b2,
                        };
                        return t;
                    }
                }
                Prim::Analytic(a) => {
                    let shape = &self.analytic[a as usize];
                    if let Some(hit) = shape.intersect(r.origin, r.direction, r.tmax) {
                        closest = Closest::Analytic {
                            slot: slot as u32,
                            shape: a,
                            hit,
                        };
                        return hit.t;
                    }
                }
            }
            f32::INFINITY
        });
        if bvh_hit.t < t_closest {
            t_closest = bvh_hit.t;
        }

        match closest {
            Closest::None => None,
            Closest::Triangle {
                slot,
                edges,
                mesh,
                tri,
                b1,
                b2,
            } => Some(self.meshes[mesh as usize].hit(tri, &edges, t_closest, b1, b2, slot)),
            Closest::Analytic { slot, shape, hit } => {
                Some(self.analytic[shape as usize].hit(hit, slot))
            }
            Closest::Plane(i) => {
                let prim = (self.prims.len() + i as usize) as u32;
                Some(self.planes[i as usize].hit(origin, dir, t_closest, prim))
            }
        }
    }

    /// Whether anything blocks the ray within (0, tmax).
    pub fn occluded(&self, ray: &Ray, tmax: f32) -> bool {
        if !(ray.origin.is_finite() && ray.dir.is_finite()) || tmax.is_nan() {
            return false;
        }
        let (origin, dir) = (Vec3A::from(ray.origin), canonical_dir(ray.dir));
        if self
            .planes
            .iter()
            .any(|plane| plane.intersect(origin, dir, tmax).is_some())
        {
            return true;
        }
        let bvh_ray = obvhs::ray::Ray::new(origin, dir, 0.0, tmax);
        !self.bvh.ray_traverse_miss(bvh_ray, |r, slot| {
            let t = match self.prims[slot] {
                Prim::Triangle { edges, .. } => edges
                    .intersect(r.origin, r.direction, r.tmax)
                    .map(|(t, _, _)| t),
                Prim::Analytic(a) => self.analytic[a as usize]
                    .intersect(r.origin, r.direction, r.tmax)
                    .map(|hit| hit.t),
            };
            t.unwrap_or(f32::INFINITY)
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

/// The ray direction with -0.0 components turned into +0.0. obvhs picks a node's near and far
/// planes by `dir < 0.0` but divides by the direction's sign, so a -0.0 component (as in
/// `-Vec3::X`) makes it swap the slab bounds and miss every box.
#[inline(always)]
fn canonical_dir(dir: Vec3) -> Vec3A {
    Vec3A::from(dir) + Vec3A::ZERO
}
