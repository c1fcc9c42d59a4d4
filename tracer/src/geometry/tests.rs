use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec3A};

use super::*;
use crate::desc::*;
use crate::material::Matte;
use crate::math::Ray;
use crate::shape::Placement;

#[path = "../../../tests/fixtures/scene.rs"]
mod fixture;
use fixture::empty_scene;

/// A scene description with the given shapes and lights, one matte material and plain values
/// elsewhere.
pub(crate) fn scene_desc(shapes: Vec<ShapeDesc>, lights: Vec<LightDesc>) -> SceneDesc {
    let camera = CameraDesc {
        kind: CameraKind::Perspective { fov: 90.0 },
        camera_to_world: Mat4::IDENTITY,
        screen_window: [-1.0, 1.0, -1.0, 1.0],
        lens_radius: 0.0,
        focal_distance: 1e30,
        autofocus: false,
        aperture: Default::default(),
        hither: 1e-3,
        yon: 1e30,
    };
    let mut desc = empty_scene(camera, 16);
    desc.integrator.max_depth = 4;
    desc.integrator.rr_strategy = RussianRoulette::None;
    desc.materials = vec![MaterialDesc::Matte(Matte {
        kd: ConstOrTexture::float(0.5),
        sigma: ConstOrTexture::float(0.0),
    })];
    desc.shapes = shapes;
    desc.lights = lights;
    desc
}

pub(crate) fn shape(geometry: Geometry, object_to_world: Mat4) -> ShapeDesc {
    ShapeDesc {
        name: "test".into(),
        geometry,
        object_to_world,
        reverse_orientation: false,
        material: MaterialId(0),
        area_light: None,
        media: Default::default(),
    }
}

pub(crate) fn mesh(positions: Vec<Vec3>, indices: Vec<[u32; 3]>) -> TriangleMesh {
    TriangleMesh {
        positions,
        normals: None,
        uvs: None,
        indices,
    }
}

pub(crate) fn sphere(radius: f32) -> Geometry {
    Geometry::Sphere(Sphere {
        radius,
        zmin: -radius,
        zmax: radius,
        phimax: 360.0,
    })
}

fn unit_triangle() -> TriangleMesh {
    mesh(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
}

fn close(a: Vec3, b: Vec3, eps: f32) -> bool {
    (a - b).abs().max_element() <= eps
}

fn down(from: Vec3) -> Ray {
    Ray::new(from, -Vec3::Z)
}

#[test]
fn triangle_hit_has_t_normal_uv_and_interpolated_shading_normal() {
    let mut m = unit_triangle();
    m.uvs = Some(vec![[0.0, 0.0], [2.0, 0.0], [0.0, 4.0]]);
    let tilted = Vec3::new(1.0, 0.0, 1.0).normalize();
    m.normals = Some(vec![Vec3::Z, Vec3::Z, tilted]);
    let desc = scene_desc(
        vec![shape(
            Geometry::Mesh(Arc::new(m)),
            Mat4::from_translation(Vec3::new(0.0, 0.0, 1.0)),
        )],
        vec![],
    );
    let geometry = SceneGeometry::build(&desc.shapes);
    assert_eq!(geometry.triangle_count(), 1);
    let hit = geometry
        .intersect(&down(Vec3::new(0.25, 0.5, 3.0)), f32::INFINITY)
        .unwrap();
    assert!((hit.t - 2.0).abs() < 1e-6, "t = {}", hit.t);
    assert!(close(hit.p, Vec3::new(0.25, 0.5, 1.0), 1e-6));
    assert!(close(hit.ng, Vec3::Z, 1e-6));
    // b1 = 0.25, b2 = 0.5: uv = 0.25 (2, 0) + 0.5 (0, 4).
    assert!((hit.uv - Vec2::new(0.5, 2.0)).length() < 1e-6);
    // u grows along +x at rate 2, so dp/du = (0.5, 0, 0).
    assert!(close(hit.dpdu, Vec3::new(0.5, 0.0, 0.0), 1e-6));
    let expected_ns = (0.25 * Vec3::Z + 0.5 * tilted + 0.25 * Vec3::Z).normalize();
    assert!(close(hit.ns, expected_ns, 1e-6), "ns = {}", hit.ns);
    assert_eq!(hit.shape, 0);

    // Default uvs (0,0), (1,0), (1,1) when the mesh has none.
    let desc = scene_desc(
        vec![shape(
            Geometry::Mesh(Arc::new(unit_triangle())),
            Mat4::IDENTITY,
        )],
        vec![],
    );
    let hit = SceneGeometry::build(&desc.shapes)
        .intersect(&down(Vec3::new(0.25, 0.5, 1.0)), f32::INFINITY)
        .unwrap();
    assert!(
        (hit.uv - Vec2::new(0.75, 0.5)).length() < 1e-6,
        "uv = {}",
        hit.uv
    );
    assert!(close(hit.ns, hit.ng, 0.0));

    // Outside the triangle, behind the origin, beyond tmax: no hit.
    let geometry = SceneGeometry::build(&desc.shapes);
    assert!(geometry
        .intersect(&down(Vec3::new(0.75, 0.5, 1.0)), f32::INFINITY)
        .is_none());
    assert!(geometry
        .intersect(&Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::Z), f32::INFINITY)
        .is_none());
    assert!(geometry
        .intersect(&down(Vec3::new(0.2, 0.2, 1.0)), 0.999)
        .is_none());
    assert!(geometry.occluded(&down(Vec3::new(0.2, 0.2, 1.0)), 1.001));
    assert!(!geometry.occluded(&down(Vec3::new(0.2, 0.2, 1.0)), 0.999));
}

#[test]
fn shading_normal_is_flipped_to_the_geometric_side() {
    let mut m = unit_triangle();
    m.normals = Some(vec![-Vec3::Z; 3]);
    let desc = scene_desc(
        vec![shape(Geometry::Mesh(Arc::new(m)), Mat4::IDENTITY)],
        vec![],
    );
    let hit = SceneGeometry::build(&desc.shapes)
        .intersect(&down(Vec3::new(0.2, 0.2, 1.0)), f32::INFINITY)
        .unwrap();
    assert!(close(hit.ng, Vec3::Z, 1e-6) && close(hit.ns, Vec3::Z, 1e-6));
}

#[test]
fn reverse_orientation_and_mirroring_transforms_set_the_front_side() {
    let ng_of = |geometry: Geometry, m: Mat4, reverse: bool, from: Vec3, dir: Vec3| {
        let mut s = shape(geometry, m);
        s.reverse_orientation = reverse;
        SceneGeometry::build(&scene_desc(vec![s], vec![]).shapes)
            .intersect(&Ray::new(from, dir), f32::INFINITY)
            .unwrap()
            .ng
    };
    let tri = || Geometry::Mesh(Arc::new(unit_triangle()));
    let mirror = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
    let above = Vec3::new(-0.2, 0.2, 1.0);
    let above_plain = Vec3::new(0.2, 0.2, 1.0);
    assert!(close(
        ng_of(tri(), Mat4::IDENTITY, false, above_plain, -Vec3::Z),
        Vec3::Z,
        1e-6
    ));
    assert!(close(
        ng_of(tri(), Mat4::IDENTITY, true, above_plain, -Vec3::Z),
        -Vec3::Z,
        1e-6
    ));
    // The mirrored triangle winds the other way in world space; its front side is still the
    // transformed object-space front (+z), unless ReverseOrientation flips it again.
    assert!(close(
        ng_of(tri(), mirror, false, above, -Vec3::Z),
        Vec3::Z,
        1e-6
    ));
    assert!(close(
        ng_of(tri(), mirror, true, above, -Vec3::Z),
        -Vec3::Z,
        1e-6
    ));

    // A sphere's front is its outside, through mirrors too; ReverseOrientation turns it in.
    let from = Vec3::new(5.0, 0.0, 0.0);
    assert!(close(
        ng_of(sphere(1.0), Mat4::IDENTITY, false, from, -Vec3::X),
        Vec3::X,
        1e-6
    ));
    assert!(close(
        ng_of(sphere(1.0), mirror, false, from, -Vec3::X),
        Vec3::X,
        1e-6
    ));
    assert!(close(
        ng_of(sphere(1.0), Mat4::IDENTITY, true, from, -Vec3::X),
        -Vec3::X,
        1e-6
    ));
    assert!(close(
        ng_of(sphere(1.0), mirror, true, from, -Vec3::X),
        -Vec3::X,
        1e-6
    ));
}

#[test]
fn sphere_hits_have_pbrt_t_normal_uv_and_tangent() {
    let centre = Vec3::new(1.0, 2.0, 3.0);
    let desc = scene_desc(
        vec![shape(sphere(2.0), Mat4::from_translation(centre))],
        vec![],
    );
    let geometry = SceneGeometry::build(&desc.shapes);
    assert_eq!(geometry.triangle_count(), 0);

    let hit = geometry
        .intersect(
            &Ray::new(centre + Vec3::new(10.0, 0.0, 0.0), -Vec3::X),
            f32::INFINITY,
        )
        .unwrap();
    assert!((hit.t - 8.0).abs() < 1e-5);
    assert!(close(hit.p, centre + Vec3::new(2.0, 0.0, 0.0), 1e-5));
    assert!(close(hit.ng, Vec3::X, 1e-6));
    // phi = 0 -> u = 0; theta = pi/2 halfway between the poles -> v = 0.5.
    assert!(
        (hit.uv - Vec2::new(0.0, 0.5)).length() < 1e-5,
        "uv = {}",
        hit.uv
    );
    assert!(
        close(hit.dpdu, Vec3::new(0.0, 2.0 * 2.0 * PI, 0.0), 1e-4),
        "dpdu = {}",
        hit.dpdu
    );

    // phi = 90 degrees -> u = 0.25; z = 2 sin(30 deg) = 1: theta = 60 degrees -> v = 2/3.
    let target = Vec3::new(0.0, 2.0 * libm::cosf(30f32.to_radians()), 1.0);
    let hit = geometry
        .intersect(
            &Ray::new(centre + target + Vec3::Y * 5.0, -Vec3::Y),
            f32::INFINITY,
        )
        .unwrap();
    assert!((hit.t - 5.0).abs() < 1e-5);
    assert!(
        (hit.uv - Vec2::new(0.25, 2.0 / 3.0)).length() < 1e-5,
        "uv = {}",
        hit.uv
    );
    assert!(close(hit.ng, target / 2.0, 1e-5));

    // From inside, the far wall; the front side is still the outside.
    let hit = geometry
        .intersect(&Ray::new(centre, Vec3::Z), f32::INFINITY)
        .unwrap();
    assert!((hit.t - 2.0).abs() < 1e-5 && close(hit.ng, Vec3::Z, 1e-5));
    assert!((hit.uv.y - 1.0).abs() < 1e-5);
}

#[test]
fn sphere_z_and_phi_limits_clip_hits() {
    // Top cut at z = 1: a ray straight down passes the hole and meets the inside bottom.
    let cut = Geometry::Sphere(Sphere {
        radius: 2.0,
        zmin: -2.0,
        zmax: 1.0,
        phimax: 360.0,
    });
    let geometry =
        SceneGeometry::build(&scene_desc(vec![shape(cut, Mat4::IDENTITY)], vec![]).shapes);
    let hit = geometry
        .intersect(&down(Vec3::new(0.0, 0.0, 10.0)), f32::INFINITY)
        .unwrap();
    assert!((hit.t - 12.0).abs() < 1e-4, "t = {}", hit.t);
    assert!(close(hit.ng, -Vec3::Z, 1e-5));
    // Off axis at x = 1.5 the ray still clears the cut (z = sqrt(4 - 2.25) = 1.32 > 1).
    let hit = geometry
        .intersect(&down(Vec3::new(1.5, 0.0, 10.0)), f32::INFINITY)
        .unwrap();
    assert!((hit.p.z + 1.75f32.sqrt()).abs() < 1e-4);

    // phimax 90: only the quarter with x, y >= 0 exists.
    let quarter = Geometry::Sphere(Sphere {
        radius: 1.0,
        zmin: -1.0,
        zmax: 1.0,
        phimax: 90.0,
    });
    let geometry =
        SceneGeometry::build(&scene_desc(vec![shape(quarter, Mat4::IDENTITY)], vec![]).shapes);
    let d = Vec3::new(1.0, 1.0, 0.0).normalize();
    let hit = geometry
        .intersect(&Ray::new(d * 5.0, -d), f32::INFINITY)
        .unwrap();
    assert!((hit.t - 4.0).abs() < 1e-5);
    assert!((hit.uv.x - 0.5).abs() < 1e-5);
    assert!(geometry
        .intersect(&Ray::new(-d * 5.0, d), f32::INFINITY)
        .is_some_and(|h| {
            // Through the missing back quarter to the inside of the front one.
            (h.t - 6.0).abs() < 1e-5 && h.ng.dot(d) > 0.99
        }));
    let side = Vec3::new(-1.0, 1.0, 0.0).normalize();
    assert!(geometry
        .intersect(&Ray::new(side * 5.0 + Vec3::Z * 0.1, -side), 5.5)
        .is_none());
}

#[test]
fn disk_and_cylinder_hits_follow_pbrt() {
    let disk = Geometry::Disk(Disk {
        height: 0.5,
        radius: 2.0,
        inner_radius: 1.0,
        phimax: 360.0,
    });
    let geometry =
        SceneGeometry::build(&scene_desc(vec![shape(disk, Mat4::IDENTITY)], vec![]).shapes);
    let hit = geometry
        .intersect(&down(Vec3::new(0.0, 1.5, 3.0)), f32::INFINITY)
        .unwrap();
    assert!((hit.t - 2.5).abs() < 1e-6 && close(hit.ng, Vec3::Z, 1e-6));
    // phi = 90 degrees, halfway between the radii.
    assert!(
        (hit.uv - Vec2::new(0.25, 0.5)).length() < 1e-5,
        "uv = {}",
        hit.uv
    );
    assert!(geometry
        .intersect(&down(Vec3::new(0.0, 0.5, 3.0)), f32::INFINITY)
        .is_none());
    assert!(geometry
        .intersect(&down(Vec3::new(0.0, 2.5, 3.0)), f32::INFINITY)
        .is_none());

    let cylinder = Geometry::Cylinder(Cylinder {
        radius: 1.0,
        zmin: -1.0,
        zmax: 3.0,
        phimax: 360.0,
    });
    let m = Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let geometry = SceneGeometry::build(&scene_desc(vec![shape(cylinder, m)], vec![]).shapes);
    // Object z = 2 is world -y = 2 after the rotation about x; the outside faces -x here.
    let target = m.transform_point3(Vec3::new(-1.0, 0.0, 2.0));
    let hit = geometry
        .intersect(&Ray::new(target - Vec3::X * 4.0, Vec3::X), f32::INFINITY)
        .unwrap();
    assert!((hit.t - 4.0).abs() < 1e-5);
    assert!(close(hit.ng, -Vec3::X, 1e-5));
    assert!(
        (hit.uv - Vec2::new(0.5, 0.75)).length() < 1e-5,
        "uv = {}",
        hit.uv
    );
    // Along the axis it never meets the wall.
    assert!(geometry
        .intersect(&Ray::new(Vec3::ZERO, Vec3::Y), f32::INFINITY)
        .is_none());
}

#[test]
fn planes_are_hit_without_the_bvh() {
    let plane = Geometry::Plane(Plane { normal: Vec3::Z });
    let desc = scene_desc(
        vec![
            shape(plane, Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0))),
            shape(Geometry::Mesh(Arc::new(unit_triangle())), Mat4::IDENTITY),
        ],
        vec![],
    );
    let geometry = SceneGeometry::build(&desc.shapes);
    let hit = geometry
        .intersect(&down(Vec3::new(5.0, 5.0, 1.0)), f32::INFINITY)
        .unwrap();
    assert!((hit.t - 2.0).abs() < 1e-6 && close(hit.ng, Vec3::Z, 1e-6) && hit.shape == 0);
    assert_eq!(hit.prim, 1, "planes come after the BVH's primitives");
    // The triangle in front of the plane wins.
    let hit = geometry
        .intersect(&down(Vec3::new(0.2, 0.2, 1.0)), f32::INFINITY)
        .unwrap();
    assert!((hit.t - 1.0).abs() < 1e-6 && hit.shape == 1);
    assert!(geometry.occluded(&down(Vec3::new(5.0, 5.0, 1.0)), 2.5));
    assert!(!geometry.occluded(&down(Vec3::new(5.0, 5.0, 1.0)), 1.5));
    assert!(geometry
        .bounds()
        .is_some_and(|(lo, hi)| lo == Vec3::ZERO && hi == Vec3::new(1.0, 1.0, 0.0)));
}

#[test]
fn bad_input_is_skipped_without_panics() {
    let bad = mesh(
        vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(f32::NAN, 0.0, 0.0)],
        vec![[0, 1, 7], [0, 0, 1], [0, 1, 3], [0, 1, 2]],
    );
    let mut with_bad_normals = bad.clone();
    with_bad_normals.normals = Some(vec![Vec3::Z]);
    let desc = scene_desc(
        vec![
            shape(Geometry::Mesh(Arc::new(bad)), Mat4::IDENTITY),
            shape(
                Geometry::Mesh(Arc::new(with_bad_normals)),
                Mat4::from_translation(Vec3::Z),
            ),
            shape(sphere(-1.0), Mat4::IDENTITY),
            shape(sphere(1.0), Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0))),
            shape(
                Geometry::Plane(Plane { normal: Vec3::ZERO }),
                Mat4::IDENTITY,
            ),
        ],
        vec![],
    );
    let geometry = SceneGeometry::build(&desc.shapes);
    assert_eq!(geometry.triangle_count(), 2);
    assert!(geometry
        .intersect(&down(Vec3::new(0.2, 0.2, 2.0)), f32::INFINITY)
        .is_some());
    let nan_ray = Ray::new(Vec3::NAN, Vec3::Z);
    assert!(geometry.intersect(&nan_ray, f32::INFINITY).is_none());
    assert!(!geometry.occluded(&nan_ray, f32::INFINITY));

    let empty = SceneGeometry::build(&scene_desc(vec![], vec![]).shapes);
    assert!(empty.intersect(&down(Vec3::Z), f32::INFINITY).is_none());
    assert!(!empty.occluded(&down(Vec3::Z), f32::INFINITY));
    assert!(empty.bounds().is_none());
}

fn random_unit(rng: &mut fastrand::Rng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - 1.0;
        let l2 = v.length_squared();
        if l2 > 1e-4 && l2 <= 1.0 {
            return v / l2.sqrt();
        }
    }
}

/// A soup of random triangles, some spheres, disks and cylinders in a 10-unit box.
fn random_scene(rng: &mut fastrand::Rng) -> SceneDesc {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for i in 0..3000u32 {
        let c = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 10.0;
        for _ in 0..3 {
            positions.push(c + random_unit(rng) * rng.f32() * 1.2);
        }
        indices.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let mut shapes = vec![shape(
        Geometry::Mesh(Arc::new(mesh(positions, indices))),
        Mat4::IDENTITY,
    )];
    for _ in 0..30 {
        let m = Mat4::from_translation(Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 10.0)
            * Mat4::from_axis_angle(random_unit(rng), rng.f32() * 6.0)
            * Mat4::from_scale(Vec3::new(0.5 + rng.f32(), 0.5 + rng.f32(), 0.5 + rng.f32()));
        let geometry = match rng.u32(0..3) {
            0 => Geometry::Sphere(Sphere {
                radius: 0.5,
                zmin: -0.5 + rng.f32() * 0.4,
                zmax: 0.5,
                phimax: 180.0 + rng.f32() * 180.0,
            }),
            1 => Geometry::Disk(Disk {
                height: 0.1,
                radius: 0.6,
                inner_radius: 0.2,
                phimax: 270.0,
            }),
            _ => Geometry::Cylinder(Cylinder {
                radius: 0.3,
                zmin: -0.5,
                zmax: 0.5,
                phimax: 300.0,
            }),
        };
        shapes.push(shape(geometry, m));
    }
    scene_desc(shapes, vec![])
}

/// The closest t by testing every primitive: what the BVH must reproduce.
fn brute_force(geometry: &SceneGeometry, ray: &Ray, tmax: f32) -> Option<(f32, u32)> {
    let (o, d) = (Vec3A::from(ray.origin), Vec3A::from(ray.dir));
    let mut best: Option<(f32, u32)> = None;
    for (slot, prim) in geometry.prims.iter().enumerate() {
        let t_best = best.map_or(tmax, |b| b.0);
        let t = match *prim {
            Prim::Triangle { edges, .. } => edges.intersect(o, d, t_best).map(|h| h.0),
            Prim::Analytic(a) => geometry.analytic[a as usize].intersect(o, d, t_best),
        };
        if let Some(t) = t {
            best = Some((t, slot as u32));
        }
    }
    best
}

#[test]
fn bvh_matches_brute_force_and_occluded_matches_intersect() {
    let mut rng = fastrand::Rng::with_seed(7);
    let geometry = SceneGeometry::build(&random_scene(&mut rng).shapes);
    assert_eq!(geometry.triangle_count(), 3000);
    assert_eq!(geometry.prims.len(), 3030);
    let (mut hits, mut blocked) = (0, 0);
    for i in 0..10_000 {
        let origin = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 14.0 - 2.0;
        let ray = Ray::new(origin, random_unit(&mut rng));
        let tmax = if i % 2 == 0 {
            f32::INFINITY
        } else {
            rng.f32() * 8.0
        };
        let expected = brute_force(&geometry, &ray, tmax);
        let got = geometry.intersect(&ray, tmax);
        match (expected, got) {
            (None, None) => {}
            (Some((t, slot)), Some(hit)) => {
                hits += 1;
                assert_eq!(hit.prim, slot, "ray {i}");
                assert_eq!(hit.t, t, "ray {i}");
                assert!((hit.p - ray.at(t)).length() < 1e-4 * (1.0 + t), "ray {i}");
                assert!((hit.ng.length() - 1.0).abs() < 1e-5);
            }
            (e, g) => panic!(
                "ray {i}: brute force {e:?}, BVH {:?}",
                g.map(|h| (h.t, h.prim))
            ),
        }
        let occluded = geometry.occluded(&ray, tmax);
        assert_eq!(occluded, expected.is_some(), "ray {i}");
        blocked += usize::from(occluded);
    }
    // Both outcomes are well represented, so the agreement means something.
    assert!(hits > 3000 && hits < 9000, "hits {hits}");
    assert_eq!(blocked, hits);
}

#[test]
fn quadric_area_sampling_density_integrates_to_the_world_area() {
    // A unit disk stretched to an ellipse with semi-axes 2 and 3: area 6 pi, while the
    // sampler works uniformly in object space. E[1 / pdf] is the world area.
    let disk = Geometry::Disk(Disk {
        height: 0.0,
        radius: 1.0,
        inner_radius: 0.0,
        phimax: 360.0,
    });
    let m = Mat4::from_rotation_y(0.3) * Mat4::from_scale(Vec3::new(2.0, 3.0, 1.0));
    let shape = placed_exactly(&disk, &m);
    let n = 200_000;
    let mut rng = fastrand::Rng::with_seed(3);
    let mean: f64 = (0..n)
        .map(|_| 1.0 / f64::from(shape.sample(Vec2::new(rng.f32(), rng.f32())).pdf_area))
        .sum::<f64>()
        / f64::from(n);
    assert!(
        (mean / f64::from(6.0 * PI) - 1.0).abs() < 1e-4,
        "mean {mean}"
    );

    // An ellipsoid (1, 1, 2): the density varies over the surface; its integral is the area
    // (by quadrature over the spheroid x = sin t cos p, y = sin t sin p, z = 2 cos t).
    let m = Mat4::from_scale(Vec3::new(1.0, 1.0, 2.0));
    let shape = placed_exactly(&sphere(1.0), &m);
    let quadrature: f64 = (0..2000)
        .map(|i| {
            // Area element of the spheroid x = sin t cos p, y = sin t sin p, z = 2 cos t.
            let t = (f64::from(i) + 0.5) / 2000.0 * std::f64::consts::PI;
            let (s, c) = libm::sincos(t);
            2.0 * std::f64::consts::PI * s * (4.0 * s * s + c * c).sqrt() * std::f64::consts::PI
                / 2000.0
        })
        .sum();
    let mean: f64 = (0..n)
        .map(|_| {
            let s = shape.sample(Vec2::new(rng.f32(), rng.f32()));
            assert!((s.p.x * s.p.x + s.p.y * s.p.y + s.p.z * s.p.z / 4.0 - 1.0).abs() < 1e-4);
            1.0 / f64::from(s.pdf_area)
        })
        .sum::<f64>()
        / f64::from(n);
    assert!(
        (mean / quadrature - 1.0).abs() < 0.01,
        "mean {mean}, area {quadrature}"
    );
}

/// An exact shape placed by `m`.
fn placed_exactly(geometry: &Geometry, m: &Mat4) -> AnalyticShape {
    let Placement::Exact(Some(surface)) = geometry.placement() else {
        panic!("{geometry:?} is not an exact shape");
    };
    AnalyticShape::new(0, surface, m, false).expect("an invertible transform")
}

/// A closed bumpy sphere of about 4 x segments^2 triangles.
fn bumpy_sphere(segments: u32) -> TriangleMesh {
    let (rows, columns) = (segments, 2 * segments);
    let mut positions = Vec::new();
    for i in 0..=rows {
        let theta = i as f32 / rows as f32 * PI;
        for j in 0..columns {
            let phi = j as f32 / columns as f32 * 2.0 * PI;
            let r = 1.0 + 0.05 * libm::sinf(7.0 * theta) * libm::sinf(9.0 * phi);
            positions.push(
                r * Vec3::new(
                    libm::sinf(theta) * libm::cosf(phi),
                    libm::sinf(theta) * libm::sinf(phi),
                    libm::cosf(theta),
                ),
            );
        }
    }
    let mut indices = Vec::new();
    for i in 0..rows {
        for j in 0..columns {
            let (a, b) = (i * columns + j, i * columns + (j + 1) % columns);
            let (c, d) = (a + columns, b + columns);
            indices.push([a, c, b]);
            indices.push([b, c, d]);
        }
    }
    mesh(positions, indices)
}

/// Build time and incoherent-ray throughput on generated meshes of ~100k and ~1M triangles,
/// next to obvhs's own triangle BVH and intersector on the same triangles. Rays from inside
/// the closed surface must all hit (misses are leaks between triangles); rays from outside aim
/// at random points of the unit ball.
/// `cargo test --release -p yat-tracer bvh_throughput -- --ignored --nocapture`
#[test]
#[ignore = "benchmark: run in release with --ignored --nocapture"]
fn bvh_throughput() {
    use rayon::prelude::*;
    use std::time::Instant;

    for segments in [158, 500] {
        let desc = scene_desc(
            vec![shape(
                Geometry::Mesh(Arc::new(bumpy_sphere(segments))),
                Mat4::IDENTITY,
            )],
            vec![],
        );
        let geometry = SceneGeometry::build(&desc.shapes);
        println!(
            "{} triangles: build {:.0} ms",
            geometry.triangle_count(),
            geometry.build_time().as_secs_f64() * 1e3
        );
        let tris: Vec<obvhs::triangle::Triangle> = geometry
            .prims
            .iter()
            .filter_map(|p| match *p {
                Prim::Triangle { edges, .. } => {
                    let [v0, v1, v2] = edges.vertices();
                    Some(obvhs::triangle::Triangle { v0, v1, v2 })
                }
                Prim::Analytic(_) => None,
            })
            .collect();
        let start = Instant::now();
        let reference = obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        println!(
            "  obvhs reference build {:.0} ms",
            start.elapsed().as_secs_f64() * 1e3
        );

        let mut rng = fastrand::Rng::with_seed(5);
        let inside: Vec<Ray> = (0..1_000_000)
            .map(|_| {
                Ray::new(
                    random_unit(&mut rng) * rng.f32() * 0.9,
                    random_unit(&mut rng),
                )
            })
            .collect();
        let outside: Vec<Ray> = (0..1_000_000)
            .map(|_| {
                let origin = random_unit(&mut rng) * 3.0;
                let target = random_unit(&mut rng) * rng.f32();
                Ray::new(origin, (target - origin).normalize())
            })
            .collect();
        let intersect = |r: &Ray| geometry.intersect(r, f32::INFINITY).is_some();
        let occluded = |r: &Ray| geometry.occluded(r, f32::INFINITY);
        let reference_intersect = |r: &Ray| {
            let ray = obvhs::ray::Ray::new_inf(r.origin.into(), canonical_dir(r.dir));
            let mut hit = obvhs::ray::RayHit::none();
            reference.ray_traverse(ray, &mut hit, |ray, id| {
                tris[reference.primitive_indices[id] as usize].intersect(ray)
            })
        };
        type Query<'a> = &'a (dyn Fn(&Ray) -> bool + Sync);
        let queries: [(&str, Query, bool); 4] = [
            ("intersect", &intersect, false),
            ("occluded", &occluded, false),
            ("intersect, all threads", &intersect, true),
            ("obvhs reference intersect", &reference_intersect, false),
        ];
        for (rays_name, rays) in [("inside", &inside), ("outside", &outside)] {
            for &(name, query, parallel) in &queries {
                let (start, cpu_start) = (Instant::now(), thread_cpu_seconds());
                let hits = if parallel {
                    rays.par_iter().filter(|r| query(r)).count()
                } else {
                    rays.iter().filter(|r| query(r)).count()
                };
                let rate = rays.len() as f64 / start.elapsed().as_secs_f64() / 1e6;
                // On a shared machine the wall clock measures the neighbours too.
                let per_cpu = match (parallel, cpu_start, thread_cpu_seconds()) {
                    (false, Some(a), Some(b)) => {
                        format!(
                            "{:6.2} M rays per CPU-second",
                            rays.len() as f64 / (b - a) / 1e6
                        )
                    }
                    _ => String::new(),
                };
                println!("  {rays_name:<8} {name:<26} {rate:6.2} M rays/s {per_cpu}, hits {hits}");
                if rays_name == "inside" {
                    assert!(
                        rays.len() - hits < rays.len() / 50_000,
                        "leaky: {hits} hits"
                    );
                }
            }
        }
    }
}

/// CPU time of the calling thread (Linux), for throughput that ignores other processes.
fn thread_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let nanos: f64 = stat.split_whitespace().next()?.parse().ok()?;
    Some(nanos * 1e-9)
}

/// Captain Falcon's shapes from the seed project (`YAT_SEED_SCENES` or
/// `<workspace>/../shared/seed-project/scenes`), or None when the seed project is absent.
fn seed_falcon() -> Option<Vec<ShapeDesc>> {
    let root = std::env::var_os("YAT_SEED_SCENES")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| {
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../shared/seed-project/scenes")
        });
    let dir = root.join("CaptainFalcon");
    if !dir.is_dir() {
        return None;
    }
    let source = crate::assets::FsSource::new(dir);
    let desc = crate::parse::parse_scene("captainfalcon.lxs", &source).expect("Falcon parses");
    Some(desc.shapes)
}

/// A ray's closest hit (slot, t, b1 and b2 bits) and any-hit answer.
type IsaAnswer = (Option<(u32, u32, u32, u32)>, bool);

/// The closest hit and the any-hit answer of every ray on one instruction set.
fn trace_on(geometry: &mut SceneGeometry, isa: Isa, rays: &[(Ray, f32)]) -> Vec<IsaAnswer> {
    assert!(geometry.set_isa(isa));
    rays.iter()
        .map(|(ray, tmax)| {
            let (o, d) = (Vec3A::from(ray.origin), canonical_dir(ray.dir));
            let hit = geometry.closest(ray, *tmax);
            if let Some(h) = hit {
                // Triangle hits carry exactly the numbers of the glam form of the test.
                if let Prim::Triangle { edges, .. } = geometry.prims[h.prim as usize] {
                    let (t, b1, b2) = edges.intersect(o, d, h.t.next_up()).expect("same test");
                    assert_eq!(
                        (t.to_bits(), b1.to_bits(), b2.to_bits()),
                        (h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()),
                        "{isa:?}"
                    );
                }
            }
            let hit = hit.map(|h| (h.prim, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()));
            (hit, geometry.occluded(ray, *tmax))
        })
        .collect()
}

/// Workers on different CPUs render the same bytes only if every instruction set returns the
/// same hit: same primitive, same t, b1 and b2 bits. Rays aim at vertices and edge midpoints
/// (where neighbouring triangles tie) as well as anywhere.
#[test]
fn every_isa_returns_bit_identical_hits() {
    let mut rng = fastrand::Rng::with_seed(11);
    let mut scenes = vec![("random", random_scene(&mut rng).shapes)];
    match seed_falcon() {
        Some(shapes) => scenes.push(("CaptainFalcon", shapes)),
        None => println!("seed project absent: CaptainFalcon skipped, random scene only"),
    }
    let isas = Isa::available();
    println!("instruction sets: {isas:?}");
    for (name, shapes) in scenes {
        let mut geometry = SceneGeometry::build(&shapes);
        let (lo, hi) = geometry.bounds().expect("finite geometry");
        let triangles: Vec<[Vec3A; 3]> = geometry
            .prims
            .iter()
            .filter_map(|p| match p {
                Prim::Triangle { edges, .. } => Some(edges.vertices()),
                Prim::Analytic(_) => None,
            })
            .collect();
        let rays: Vec<(Ray, f32)> = (0..60_000)
            .map(|i| {
                let origin = lo + (hi - lo) * Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 1.4
                    - (hi - lo) * 0.2;
                let [a, b, c] = triangles[rng.usize(..triangles.len())];
                let target = match i % 3 {
                    0 => a,
                    1 => (b + c) * 0.5,
                    _ => a + (b - a) * rng.f32() + (c - a) * rng.f32() * 0.5,
                };
                let dir = (Vec3::from(target) - origin).normalize_or_zero();
                let dir = if i % 5 == 4 {
                    random_unit(&mut rng)
                } else {
                    dir
                };
                let tmax = if i % 4 == 3 {
                    rng.f32() * (hi - lo).length()
                } else {
                    f32::INFINITY
                };
                (Ray::new(origin, dir), tmax)
            })
            .collect();
        let reference = trace_on(&mut geometry, Isa::Scalar, &rays);
        let hits = reference.iter().filter(|r| r.0.is_some()).count();
        assert!(hits > rays.len() / 2, "{name}: only {hits} hits");
        for &isa in &isas[1..] {
            let got = trace_on(&mut geometry, isa, &rays);
            for (i, (r, g)) in reference.iter().zip(&got).enumerate() {
                assert_eq!(r, g, "{name}, ray {i}: Scalar vs {isa:?}");
            }
        }
        println!(
            "{name}: {} rays, {hits} hits, identical on {isas:?}",
            rays.len()
        );
    }
}

/// Shapes named to [`SceneGeometry::cross_in_occlusion`] (`null` surfaces) no longer block
/// shadow rays, whatever their kind, while closest hits still find them; the others still block.
#[test]
fn occlusion_looks_through_crossed_shapes_only() {
    // Stacked under a ray going down from z = 10: a sphere at z = 6, a triangle at z = 4, a
    // triangle sharing a packet with it at z = 3 off to the side, a plane at z = 0.
    let big = |z: f32| {
        mesh(
            vec![
                Vec3::new(-5.0, -5.0, z),
                Vec3::new(5.0, -5.0, z),
                Vec3::new(0.0, 5.0, z),
            ],
            vec![[0, 1, 2]],
        )
    };
    let aside = mesh(
        vec![
            Vec3::new(20.0, 20.0, 3.0),
            Vec3::new(21.0, 20.0, 3.0),
            Vec3::new(20.0, 21.0, 3.0),
        ],
        vec![[0, 1, 2]],
    );
    let shapes = vec![
        shape(
            sphere(1.0),
            Mat4::from_translation(Vec3::new(0.0, 0.0, 6.0)),
        ),
        shape(Geometry::Mesh(Arc::new(big(4.0))), Mat4::IDENTITY),
        shape(Geometry::Mesh(Arc::new(aside)), Mat4::IDENTITY),
        shape(Geometry::Plane(Plane { normal: Vec3::Z }), Mat4::IDENTITY),
    ];
    let ray = down(Vec3::new(0.0, 0.0, 10.0));
    let blocked_before = |crossed: [bool; 4], tmax: f32| {
        let mut geometry = SceneGeometry::build(&shapes);
        geometry.cross_in_occlusion(crossed.to_vec());
        let first = geometry.intersect(&ray, f32::INFINITY).map(|h| h.shape);
        (geometry.occluded(&ray, tmax), first)
    };
    // Nothing crossed: the sphere blocks; it is also the first hit.
    assert_eq!(blocked_before([false; 4], 100.0), (true, Some(0)));
    // The sphere crossed: the triangle at z = 4 blocks; the sphere is still the first hit.
    assert_eq!(
        blocked_before([true, false, false, false], 100.0),
        (true, Some(0))
    );
    // Sphere and triangle crossed: the plane blocks (at 10), not within 9.
    assert_eq!(
        blocked_before([true, true, false, false], 100.0),
        (true, Some(0))
    );
    assert!(!blocked_before([true, true, false, false], 9.0).0);
    // Everything in the way crossed: nothing blocks.
    assert!(!blocked_before([true, true, false, true], 100.0).0);
    // Only the plane crossed: the others block.
    assert!(blocked_before([false, false, false, true], 100.0).0);
    assert!(blocked_before([true, false, true, true], 100.0).0);
}
