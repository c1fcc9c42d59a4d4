//! The BVH and lights on real scenes: the seed project's scenes (read at run time from
//! `<workspace>/../shared/seed-project/scenes`, or `YAT_SEED_SCENES`) and the project's own.
//! Prints build times and ray throughput, and checks that intersect, occluded and light
//! sampling agree with one another on every scene.
//!
//! `cargo test --release -p yat-tracer --test integration geometry_on_scenes -- --ignored --nocapture`

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::{Vec2, Vec3};
use yat_tracer::assets::FsSource;
use yat_tracer::camera::Camera;
use yat_tracer::math::{offset_origin, Frame, Ray};
use yat_tracer::parse::parse_scene;

use crate::area_texture::geometry_and_lights;
use crate::util::{seed_scenes, workspace_root};

fn scene_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<_> = entries.flatten().map(|e| e.path()).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            scene_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "lxs") {
            out.push(path);
        }
    }
}

#[test]
#[ignore = "slow on real meshes: run in release with --ignored --nocapture"]
fn bvh_and_lights_on_real_scenes() {
    let mut files = Vec::new();
    if let Some(seed) = seed_scenes() {
        scene_files(&seed, &mut files);
    }
    scene_files(&workspace_root().join("scenes"), &mut files);
    assert!(!files.is_empty());

    for file in files {
        let source = FsSource::for_main_file(&file);
        let name = file.file_name().unwrap().to_string_lossy().to_string();
        let desc = match parse_scene(&name, &source) {
            Ok(desc) => desc,
            Err(e) => {
                println!("{}: not parsed ({e})", file.display());
                continue;
            }
        };
        let (geometry, lights) = geometry_and_lights(&desc, &source, &file.display().to_string());
        if lights.is_empty() {
            println!("{name:<40} no lights (a fragment meant for Include?)");
            continue;
        }

        let (w, h) = (160u32, 120u32);
        let camera = Camera::new(&desc.camera, w, h);
        let mut rng = fastrand::Rng::with_seed(1);
        let primary: Vec<Ray> = (0..w * h)
            .filter_map(|i| {
                let film = Vec2::new((i % w) as f32 + rng.f32(), (i / w) as f32 + rng.f32());
                camera.generate_ray(film, Vec2::new(rng.f32(), rng.f32()))
            })
            .collect();
        let start = Instant::now();
        let hits: Vec<_> = primary
            .iter()
            .map(|r| geometry.intersect(r, f32::INFINITY))
            .collect();
        let primary_rate = primary.len() as f64 / start.elapsed().as_secs_f64() / 1e6;

        // Diffuse-like bounces from the visible points, on the side the camera sees.
        let bounces: Vec<Ray> = hits
            .iter()
            .zip(&primary)
            .filter_map(|(hit, ray)| {
                let hit = hit.as_ref()?;
                let n = if hit.ng.dot(ray.dir) < 0.0 {
                    hit.ng
                } else {
                    -hit.ng
                };
                let (r, phi) = (rng.f32().sqrt(), rng.f32() * std::f32::consts::TAU);
                let local = Vec3::new(
                    r * libm::cosf(phi),
                    r * libm::sinf(phi),
                    (1.0 - r * r).max(0.0).sqrt(),
                );
                let dir = Frame::from_normal(n).to_world(local).normalize();
                Some(Ray::new(offset_origin(hit.p, hit.ng, dir), dir))
            })
            .collect();
        let start = Instant::now();
        let bounce_hits = bounces
            .iter()
            .filter(|r| geometry.intersect(r, f32::INFINITY).is_some())
            .count();
        let bounce_rate = bounces.len() as f64 / start.elapsed().as_secs_f64() / 1e6;
        let occluded = bounces
            .iter()
            .filter(|r| geometry.occluded(r, f32::INFINITY))
            .count();
        assert_eq!(
            occluded,
            bounce_hits,
            "{}: occluded vs intersect",
            file.display()
        );

        // Light samples from the visible points: the shadow ray to an area-light point stops
        // just short of it, and a BSDF-style ray along the sample hits the light with the
        // density the sample reported.
        let mut agreed = 0;
        for hit in hits.iter().flatten().take(2000) {
            let Some(s) = lights.sample(hit.p, None, rng.f32(), Vec2::new(rng.f32(), rng.f32()))
            else {
                continue;
            };
            if s.delta || !s.dist.is_finite() {
                continue;
            }
            let origin = offset_origin(hit.p, hit.ng, s.wi);
            let Some(light_hit) = geometry.intersect(&Ray::new(origin, s.wi), f32::INFINITY) else {
                continue;
            };
            if (light_hit.t - s.dist).abs() > 1e-3 * s.dist || light_hit.ng.dot(-s.wi) < 0.05 {
                continue; // occluded, or grazing where f32 cannot agree
            }
            let pdf = lights.pdf_hit(hit.p, &light_hit);
            assert!(
                (pdf / s.pdf - 1.0).abs() < 0.02,
                "{}: pdf_hit {pdf} vs sample {}",
                file.display(),
                s.pdf
            );
            agreed += 1;
        }
        println!(
            "{name:<40} {:>9} tris  build {:>6.0} ms  primary {:>5.2} M/s ({:>3.0}% hit)  \
             bounce {:>5.2} M/s  area-light pdf checks {agreed}",
            geometry.triangle_count(),
            geometry.build_time().as_secs_f64() * 1e3,
            primary_rate,
            100.0 * hits.iter().flatten().count() as f64 / primary.len() as f64,
            bounce_rate,
        );
    }
}
