//! Adaptive sampling on a whole render: against a converged reference, the rounds spend the
//! same samples as a uniform render for less error, on a scene with a flat floor and a caustic.

use std::sync::Arc;

use glam::Vec3;

use yat_tracer::assets::MemorySource;
use yat_tracer::desc::LatLongConvention;
use yat_tracer::film::Film;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::adaptive::{next_round, AdaptiveSettings, Round};
use yat_tracer::render::unit::BLOCK_SIZE;
use yat_tracer::render::{plan_units, RenderScene, RenderSettings};

/// A matte floor under a dim sky, lit by a small bright sphere light through a glass ball: the
/// floor is smooth except for the ball's caustic and shadow, which path tracing finds rarely.
const CAUSTIC: &str = r#"Film "fleximage" "integer xresolution" [48] "integer yresolution" [48]
PixelFilter "box"
SurfaceIntegrator "path" "integer maxdepth" [8]
LookAt 0 -2.2 2.2  0 0 0  0 0 1
Camera "perspective" "float fov" [50]
WorldBegin
LightSource "infinite" "color L" [0.3 0.3 0.3]
AttributeBegin
  Material "matte" "color Kd" [0.7 0.7 0.7]
  Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-3 -3 0  3 -3 0  3 3 0  -3 3 0]
AttributeEnd
AttributeBegin
  Translate 0.2 0.1 0.5
  Material "glass" "float index" [1.5]
  Shape "sphere" "float radius" 0.5
AttributeEnd
AttributeBegin
  Translate 0.6 0.4 2.0
  AreaLightSource "area" "color L" [300 280 250]
  Shape "sphere" "float radius" 0.05
AttributeEnd
WorldEnd
"#;

fn settings(spp: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        width: 48,
        height: 48,
        spp,
        max_depth: 8,
        seed,
        latlong: LatLongConvention::Seed,
        transport: Default::default(),
        aovs: Default::default(),
    }
}

fn build(settings: &RenderSettings) -> RenderScene {
    let mut source = MemorySource::new();
    source.insert("caustic.lxs", Arc::from(CAUSTIC.as_bytes()));
    let desc = parse_scene("caustic.lxs", &source).expect("parses");
    RenderScene::build(&desc, &source, settings).expect("builds")
}

/// A uniform render: the film and its camera samples.
fn uniform(spp: u32, seed: u64) -> (Film, u64) {
    let s = settings(spp, seed);
    let scene = build(&s);
    let mut film = Film::new(scene.frame());
    let mut samples = 0;
    for unit in plan_units(&s) {
        let (buffer, stats) = scene.render_unit(&unit);
        film.add(&buffer).unwrap();
        samples += stats.samples;
    }
    (film, samples)
}

/// An adaptive render to the end of its rounds: the film and its camera samples.
fn adaptive(max_spp: u32, seed: u64, adaptive: &AdaptiveSettings) -> (Film, u64) {
    let s = settings(max_spp, seed);
    let scene = build(&s);
    let mut film = Film::adaptive(scene.frame());
    let mut round = Round::first(&s, adaptive);
    let mut samples = 0;
    loop {
        for unit in round.units(&s, adaptive) {
            let (buffer, stats) = scene.render_unit(&unit);
            film.add(&buffer).unwrap();
            samples += stats.samples;
        }
        match next_round(&film, &round, &s, adaptive) {
            Some(next) => round = next,
            None => return (film, samples),
        }
    }
}

fn mse(a: &[Vec3], b: &[Vec3]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| f64::from((*p - *q).length_squared()))
        .sum();
    sum / (3 * a.len()) as f64
}

#[test]
fn adaptive_sampling_beats_uniform_at_the_same_samples() {
    // The reference: the mean of two 2048-spp renders of other seeds, whose own noise,
    // MSE(a, b) / 4, is taken off every error below.
    let (a, b) = (uniform(2048, 7).0.radiance(), uniform(2048, 8).0.radiance());
    let reference: Vec<Vec3> = a.iter().zip(&b).map(|(p, q)| (*p + *q) / 2.0).collect();
    let reference_noise = mse(&a, &b) / 4.0;
    // The caustic's rare bright paths decide both how many samples a run spends (a block that
    // caught one in round 0 looks noisy) and its error (where they land), so one seed says
    // little: four seeds, each adaptive run against a uniform run of its samples and seed.
    let settings = AdaptiveSettings {
        // The image's RMS error over its mean brightness: at 0.05 the runs stop between about
        // 100 and 500 spp on average.
        threshold: 0.05,
        min_spp: 16,
    };
    let pixels = 48 * 48;
    let (mut e_adaptive, mut e_uniform) = (0.0, 0.0);
    for seed in 0..4 {
        let (adaptive_film, adaptive_samples) = adaptive(512, seed, &settings);
        let spp = (adaptive_samples / pixels) as u32;
        assert!(
            (32..=512).contains(&spp),
            "the rounds stop after round 0 and at the maximum at most: {spp} spp on average"
        );
        let (uniform_film, uniform_samples) = uniform(spp, seed);
        assert!(uniform_samples <= adaptive_samples);
        let adaptive_error = mse(&adaptive_film.radiance(), &reference) - reference_noise;
        let uniform_error = mse(&uniform_film.radiance(), &reference) - reference_noise;
        eprintln!("seed {seed}, {spp} spp: MSE adaptive {adaptive_error:.4e}, uniform {uniform_error:.4e}");
        e_adaptive += adaptive_error;
        e_uniform += uniform_error;
    }
    assert!(
        e_adaptive < 0.8 * e_uniform,
        "summed MSE adaptive {e_adaptive:.4e} vs uniform {e_uniform:.4e}"
    );
}

/// A bright triangle straight in view on black, under a wide filter (blackmanharris at its
/// default half-width 4 reaches a whole block each side: 9 source planes): a pixel's radiance is the filter's
/// average over the edge, noisy only through where its samples fall.
const EDGE: &str = r#"Film "fleximage" "integer xresolution" [48] "integer yresolution" [48]
PixelFilter "blackmanharris"
SurfaceIntegrator "path" "integer maxdepth" [1]
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [40]
WorldBegin
AttributeBegin
  AreaLightSource "area" "color L" [4 4 4]
  Shape "trianglemesh" "integer indices" [0 1 2] "point P" [-1.3 -1.1 0  1.5 -0.4 0  -0.2 1.4 0]
AttributeEnd
WorldEnd
"#;

#[test]
fn blocks_with_more_samples_do_not_pull_their_neighbours_edges() {
    let mut source = MemorySource::new();
    source.insert("edge.lxs", Arc::from(EDGE.as_bytes()));
    let desc = parse_scene("edge.lxs", &source).expect("parses");
    let s = RenderSettings {
        max_depth: 1,
        ..settings(1024, 0)
    };
    let scene = RenderScene::build(&desc, &source, &s).expect("builds");
    let a = AdaptiveSettings {
        threshold: 0.05,
        min_spp: 16,
    };
    // Round 0 for all, then every other block (a checkerboard) on to 1024 samples: the
    // densities of neighbouring blocks differ 64 times.
    let mut film = Film::adaptive(scene.frame());
    let mut round = Round::first(&s, &a);
    loop {
        for unit in round.units(&s, &a) {
            film.add(&scene.render_unit(&unit).0).unwrap();
        }
        let Some((_, end)) = a.round_range(round.index + 1, s.spp) else {
            break;
        };
        let columns = (48 / BLOCK_SIZE) as usize;
        let planned = (0..round.planned.len())
            .map(|b| {
                if (b % columns + b / columns).is_multiple_of(2) {
                    end
                } else {
                    16
                }
            })
            .collect();
        round = Round {
            index: round.index + 1,
            planned,
        };
    }
    assert_eq!(film.block_samples()[..3], [1024, 16, 1024]);
    // The reference: every pixel at 1024 samples.
    let mut uniform = Film::new(scene.frame());
    for unit in plan_units(&s) {
        uniform.add(&scene.render_unit(&unit).0).unwrap();
    }
    // Mean squared difference to it over the pixels of the 16-sample blocks: as the film weighs
    // each block's samples, and as a plain weighted mean of every sample reaching the pixel
    // would (a pixel by a dense block then leans toward that block's side of the edge).
    let (mut weighed, mut plain, mut count) = (0.0f64, 0.0f64, 0);
    for y in 0..48u32 {
        for x in 0..48u32 {
            if (x / BLOCK_SIZE + y / BLOCK_SIZE) % 2 == 1 {
                let reference = uniform.pixel(x, y).x;
                let i = (y * 48 + x) as usize;
                weighed += f64::from(film.pixel(x, y).x - reference).powi(2);
                plain += f64::from(film.plain_pixel(i).x - reference).powi(2);
                count += 1;
            }
        }
    }
    let (weighed, plain) = (weighed / f64::from(count), plain / f64::from(count));
    eprintln!("MSE on the sparse blocks: weighed {weighed:.4e}, plain {plain:.4e}");
    // Measured: weighed 0.148 (the 16-sample blocks' noise), plain 134.
    assert!(
        plain > 100.0 * weighed,
        "plain {plain} vs weighed {weighed}"
    );
}
