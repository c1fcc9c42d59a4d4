//! Traversal benchmark (issue #20, point 3): the triangles of a scene (loaded through YAT's
//! parser, transformed to world space as the renderer does) and two ray sets, traced on one
//! thread by obvhs's own CWBVH traversal (with obvhs's triangle test), by YAT's
//! `SceneGeometry::closest` on each instruction set (and `intersect`, which adds the surface
//! data the renderer reads: "YAT+surface"), and by Embree 3 (`embree-trace`, built by
//! `bench/traversal/setup.sh`). Prints rays per CPU-second (best of the rounds, the three
//! interleaved in each round) and YAT/Embree ratios, after checking that all three agree on
//! which rays hit and where.
//!
//! Rays: coherent = the scene camera's rays through every pixel of a `--width` image, in
//! scanline order; incoherent = one bounce from each camera hit (YAT's hit point, offset off
//! the surface, uniform direction over the hemisphere facing the incoming ray), in pixel
//! order. Closest hit and any hit use tmax = infinity.
//!
//! `cargo run --release -p yat-traversal -- --embree target/embree-trace`

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, ensure, Context, Result};
use clap::Parser;
use glam::{Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::ray::RayHit;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use yat_tracer::assets::FsSource;
use yat_tracer::camera::Camera;
use yat_tracer::desc::SceneDesc;
use yat_tracer::geometry::{Isa, SceneGeometry};
use yat_tracer::math::{Frame, Ray};
use yat_tracer::parse::parse_scene;
use yat_tracer::shape::Geometry;

/// Hits agree when both miss, or both hit with t within this relative tolerance (the three
/// triangle tests round differently; a different primitive at the same t is the same hit).
const T_TOLERANCE: f32 = 1e-4;
/// Disagreements allowed per ray set, as a fraction of its rays: rays through shared edges and
/// vertices, where the triangle tests' rounding decides.
const ALLOWED_DISAGREEMENT: f64 = 2e-4;

#[derive(Parser)]
struct Args {
    /// Scene file whose meshes are traced.
    #[arg(
        long,
        default_value = "/work/shared/seed-project/scenes/CaptainFalcon/captainfalcon.lxs"
    )]
    scene: PathBuf,
    /// The `embree-trace` program (bench/traversal/setup.sh); without it Embree is skipped.
    #[arg(long)]
    embree: Option<PathBuf>,
    /// Embree build quality: low, medium or high (spatial splits).
    #[arg(long, default_value = "high")]
    quality: String,
    /// Width of the camera-ray image (height follows the film's aspect).
    #[arg(long, default_value_t = 960)]
    width: u32,
    /// Rounds; each config's best round is reported.
    #[arg(long, default_value_t = 5)]
    rounds: usize,
}

/// A ray with its tmax, as all three tracers receive it.
#[derive(Clone, Copy)]
struct BenchRay {
    ray: Ray,
    tmax: f32,
}

/// One tracer's answers for a ray set: per ray, the hit distance (None = miss) and whether
/// the any-hit query found something.
struct Answers {
    closest: Vec<Option<f32>>,
    any: Vec<bool>,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let desc = load(&args.scene)?;
    let (positions, indices) = world_triangles(&desc);
    ensure!(
        !indices.is_empty(),
        "{} has no triangles",
        args.scene.display()
    );
    // YAT's geometry from the meshes only, so that all three trace the same triangles.
    let shapes: Vec<_> = desc
        .shapes
        .iter()
        .filter(|s| matches!(s.geometry, Geometry::Mesh(_)))
        .cloned()
        .collect();
    let mut yat = SceneGeometry::build(&shapes);
    ensure!(
        yat.triangle_count() == indices.len(),
        "YAT kept {} of {} triangles",
        yat.triangle_count(),
        indices.len()
    );
    let triangles: Vec<Triangle> = indices
        .iter()
        .map(|t| {
            let [v0, v1, v2] = t.map(|i| Vec3A::from(positions[i as usize]));
            Triangle { v0, v1, v2 }
        })
        .collect();
    let aabbs: Vec<Aabb> = triangles.iter().map(|t| t.aabb()).collect();
    let obvhs_bvh = build_cwbvh(
        &aabbs,
        BvhBuildParams::slow_build(),
        &mut Default::default(),
    );
    println!(
        "{}: {} triangles; obvhs CWBVH8 slow_build over triangle boxes (YAT's build), Embree \
         3 build quality {}",
        args.scene.display(),
        indices.len(),
        args.quality
    );

    let coherent = camera_rays(&desc, args.width);
    let incoherent = bounce_rays(&yat, &coherent);
    let tmp = std::env::temp_dir().join(format!("yat-traversal-{}", std::process::id()));
    std::fs::create_dir_all(&tmp)?;
    let geometry_file = tmp.join("geometry.bin");
    write_geometry(&geometry_file, &positions, &indices)?;

    let isas = Isa::available();
    for (set_name, rays) in [("coherent", &coherent), ("incoherent", &incoherent)] {
        let ray_file = tmp.join(format!("{set_name}.bin"));
        write_rays(&ray_file, rays)?;
        // Best seconds per (tracer, query): closest, any.
        let mut best: Vec<(String, [f64; 2])> = Vec::new();
        let mut record = |name: String, secs: [f64; 2]| {
            match best.iter_mut().find(|(n, _)| *n == name) {
                Some((_, b)) => {
                    b[0] = b[0].min(secs[0]);
                    b[1] = b[1].min(secs[1]);
                }
                None => best.push((name, secs)),
            };
        };
        let mut answers: Vec<(String, Answers)> = Vec::new();
        for round in 0..args.rounds {
            for &isa in &isas {
                assert!(yat.set_isa(isa));
                let (secs, a) = trace_yat(&yat, rays, false);
                record(format!("YAT {isa:?}"), secs);
                if round == 0 {
                    answers.push((format!("YAT {isa:?}"), a));
                }
            }
            // What the renderer calls: the closest hit plus its surface data (normals, uvs).
            let (secs, _) = trace_yat(&yat, rays, true);
            record("YAT+surface".into(), secs);
            let (secs, a) = trace_obvhs(&obvhs_bvh, &triangles, rays);
            record("obvhs".into(), secs);
            if round == 0 {
                answers.push(("obvhs".into(), a));
            }
            if let Some(embree) = &args.embree {
                let out = tmp.join("out.bin");
                let (secs, a) =
                    trace_embree(embree, &args.quality, &geometry_file, &ray_file, &out)?;
                record("Embree".into(), secs);
                if round == 0 {
                    answers.push(("Embree".into(), a));
                }
            }
        }
        yat.set_isa(Isa::best());

        println!("\n{set_name} rays: {}", rays.len());
        let hits = answers[0].1.closest.iter().filter(|h| h.is_some()).count();
        println!(
            "  hits {hits} ({:.1}%)",
            100.0 * hits as f64 / rays.len() as f64
        );
        let reference = &answers[0];
        let mut failed = false;
        for (name, a) in &answers[1..] {
            let closest = disagreements(&reference.1.closest, &a.closest);
            let any = reference
                .1
                .any
                .iter()
                .zip(&a.any)
                .filter(|(x, y)| x != y)
                .count();
            let allowed = (rays.len() as f64 * ALLOWED_DISAGREEMENT).ceil() as usize;
            let ok = closest <= allowed && any <= allowed;
            failed |= !ok;
            println!(
                "  {} vs {name}: {closest} closest-hit and {any} any-hit disagreements (allowed \
                 {allowed}) {}",
                reference.0,
                if ok { "ok" } else { "FAILED" }
            );
        }
        let embree = best.iter().find(|(n, _)| n == "Embree").map(|(_, s)| *s);
        println!(
            "  {:<12} {:>14} {:>14} {:>10} {:>10}",
            "tracer", "closest M/s", "any M/s", "closest/E", "any/E"
        );
        for (name, secs) in &best {
            let rate = secs.map(|s| rays.len() as f64 / s / 1e6);
            let ratio =
                |q: usize| embree.map_or("-".to_string(), |e| format!("{:.2}", e[q] / secs[q]));
            println!(
                "  {name:<12} {:>14.2} {:>14.2} {:>10} {:>10}",
                rate[0],
                rate[1],
                ratio(0),
                ratio(1)
            );
        }
        if failed {
            bail!("{set_name}: the tracers disagree on hits");
        }
    }
    std::fs::remove_dir_all(&tmp).ok();
    Ok(())
}

fn load(path: &Path) -> Result<SceneDesc> {
    let main = path
        .file_name()
        .and_then(|n| n.to_str())
        .context("scene path has no file name")?;
    parse_scene(main, &FsSource::for_main_file(path))
        .with_context(|| format!("cannot parse {}", path.display()))
}

/// Every mesh's triangles in world space, transformed as `SceneGeometry` does, without the
/// triangles it drops (zero area, out-of-range indices).
fn world_triangles(desc: &SceneDesc) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (mut positions, mut indices) = (Vec::new(), Vec::new());
    for shape in &desc.shapes {
        let Geometry::Mesh(mesh) = &shape.geometry else {
            continue;
        };
        let base = positions.len() as u32;
        positions.extend(
            mesh.positions
                .iter()
                .map(|&p| shape.object_to_world.transform_point3(p)),
        );
        let world = &positions[base as usize..];
        indices.extend(mesh.indices.iter().filter_map(|tri| {
            let valid = tri.iter().all(|&i| (i as usize) < world.len()) && {
                let [p0, p1, p2] = tri.map(|i| world[i as usize]);
                (p1 - p0).cross(p2 - p0).normalize_or_zero() != Vec3::ZERO
            };
            valid.then(|| tri.map(|i| i + base))
        }));
    }
    (positions, indices)
}

fn camera_rays(desc: &SceneDesc, width: u32) -> Vec<BenchRay> {
    let aspect = desc.film.yresolution as f32 / desc.film.xresolution as f32;
    let height = ((width as f32 * aspect).round() as u32).max(1);
    let camera = Camera::new(&desc.camera, width, height);
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .filter_map(|(x, y)| {
            let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            camera
                .generate_ray(film, Vec2::splat(0.5))
                .map(|ray| BenchRay {
                    ray,
                    tmax: f32::INFINITY,
                })
        })
        .collect()
}

fn bounce_rays(geometry: &SceneGeometry, camera: &[BenchRay]) -> Vec<BenchRay> {
    let mut rng = fastrand::Rng::with_seed(20);
    camera
        .iter()
        .filter_map(|r| geometry.intersect(&r.ray, r.tmax))
        .zip(camera)
        .map(|(hit, r)| {
            let n = if hit.ng.dot(r.ray.dir) > 0.0 {
                -hit.ng
            } else {
                hit.ng
            };
            // Uniform over the hemisphere around n.
            let z = rng.f32();
            let phi = std::f32::consts::TAU * rng.f32();
            let s = (1.0 - z * z).max(0.0).sqrt();
            let local = Vec3::new(s * libm::cosf(phi), s * libm::sinf(phi), z);
            let dir = Frame::from_normal(n).to_world(local).normalize();
            let offset = 1e-4 * (1.0 + hit.p.abs().max_element());
            BenchRay {
                ray: Ray::new(hit.p + n * offset, dir),
                tmax: f32::INFINITY,
            }
        })
        .collect()
}

/// CPU time of the calling thread: the measure that ignores the other processes of a shared
/// machine (Embree's side reads the same clock).
fn thread_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes the timespec it is given.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64
}

fn timed<T>(f: impl FnOnce() -> T) -> (f64, T) {
    let start = thread_seconds();
    let out = f();
    (thread_seconds() - start, out)
}

/// YAT's closest hit (`SceneGeometry::closest`, the traversal alone, or with `surface` the
/// renderer's `intersect`, which adds the hit's surface data) and any hit.
fn trace_yat(geometry: &SceneGeometry, rays: &[BenchRay], surface: bool) -> ([f64; 2], Answers) {
    let (c, closest) = timed(|| {
        rays.iter()
            .map(|r| match surface {
                false => geometry.closest(&r.ray, r.tmax).map(|h| h.t),
                true => geometry.intersect(&r.ray, r.tmax).map(|h| h.t),
            })
            .collect::<Vec<_>>()
    });
    let (a, any) = timed(|| {
        rays.iter()
            .map(|r| geometry.occluded(&r.ray, r.tmax))
            .collect::<Vec<_>>()
    });
    ([c, a], Answers { closest, any })
}

fn trace_obvhs(
    bvh: &obvhs::cwbvh::CwBvh,
    triangles: &[Triangle],
    rays: &[BenchRay],
) -> ([f64; 2], Answers) {
    // obvhs needs +0.0 for zero direction components (see geometry::canonical_dir).
    let ray = |r: &BenchRay| {
        obvhs::ray::Ray::new(
            r.ray.origin.into(),
            Vec3A::from(r.ray.dir) + Vec3A::ZERO,
            0.0,
            r.tmax,
        )
    };
    let (c, closest) = timed(|| {
        rays.iter()
            .map(|r| {
                let mut hit = RayHit::none();
                bvh.ray_traverse(ray(r), &mut hit, |ray, id| {
                    triangles[bvh.primitive_indices[id] as usize].intersect(ray)
                })
                .then_some(hit.t)
            })
            .collect::<Vec<_>>()
    });
    let (a, any) = timed(|| {
        rays.iter()
            .map(|r| {
                !bvh.ray_traverse_miss(ray(r), |ray, id| {
                    triangles[bvh.primitive_indices[id] as usize].intersect(ray)
                })
            })
            .collect::<Vec<_>>()
    });
    ([c, a], Answers { closest, any })
}

fn trace_embree(
    program: &Path,
    quality: &str,
    geometry: &Path,
    rays: &Path,
    out: &Path,
) -> Result<([f64; 2], Answers)> {
    let status = Command::new(program)
        .args([Path::new(quality), geometry, rays, out])
        .status()
        .with_context(|| format!("cannot run {}", program.display()))?;
    ensure!(status.success(), "{} failed: {status}", program.display());
    let bytes = std::fs::read(out)?;
    ensure!(
        bytes.len() >= 16 && (bytes.len() - 16) % 9 == 0,
        "bad embree output"
    );
    let f64_at = |i: usize| f64::from_le_bytes(bytes[i..i + 8].try_into().expect("8 bytes"));
    let (mut closest, mut any) = (Vec::new(), Vec::new());
    for rec in bytes[16..].chunks_exact(9) {
        let prim = u32::from_le_bytes(rec[0..4].try_into().expect("4 bytes"));
        let t = f32::from_le_bytes(rec[4..8].try_into().expect("4 bytes"));
        closest.push((prim != u32::MAX).then_some(t));
        any.push(rec[8] != 0);
    }
    Ok(([f64_at(0), f64_at(8)], Answers { closest, any }))
}

fn disagreements(a: &[Option<f32>], b: &[Option<f32>]) -> usize {
    a.iter()
        .zip(b)
        .filter(|(x, y)| match (x, y) {
            (None, None) => false,
            (Some(x), Some(y)) => (x - y).abs() > T_TOLERANCE * x.abs().max(1.0),
            _ => true,
        })
        .count()
}

fn write_geometry(path: &Path, positions: &[Vec3], indices: &[[u32; 3]]) -> Result<()> {
    let mut out = Vec::with_capacity(8 + positions.len() * 12 + indices.len() * 12);
    out.extend((positions.len() as u32).to_le_bytes());
    for p in positions {
        for v in p.to_array() {
            out.extend(v.to_le_bytes());
        }
    }
    out.extend((indices.len() as u32).to_le_bytes());
    for t in indices {
        for i in t {
            out.extend(i.to_le_bytes());
        }
    }
    Ok(std::fs::write(path, out)?)
}

fn write_rays(path: &Path, rays: &[BenchRay]) -> Result<()> {
    let mut out = Vec::with_capacity(4 + rays.len() * 32);
    out.extend((rays.len() as u32).to_le_bytes());
    for r in rays {
        let floats = [r.ray.origin.to_array(), r.ray.dir.to_array()].concat();
        for v in floats.into_iter().chain([0.0, r.tmax]) {
            out.extend(v.to_le_bytes());
        }
    }
    Ok(std::fs::write(path, out)?)
}
