//! Adaptive sampling on a whole render: against a converged reference, the rounds spend the
//! same samples as a uniform render for less error, on a scene with a flat floor and a caustic.

use std::sync::Arc;

use yat_tracer::assets::MemorySource;
use yat_tracer::desc::LatLongConvention;
use yat_tracer::film::Film;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::adaptive::{next_round, AdaptiveSettings, Round};
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
fn adaptive(max_spp: u32, adaptive: &AdaptiveSettings) -> (Film, u64) {
    let s = settings(max_spp, 0);
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

fn mse(a: &Film, b: &Film) -> f64 {
    let (a, b) = (a.radiance(), b.radiance());
    let sum: f64 = a
        .iter()
        .zip(&b)
        .map(|(p, q)| f64::from((*p - *q).length_squared()))
        .sum();
    sum / (3 * a.len()) as f64
}

#[test]
fn adaptive_sampling_beats_uniform_at_the_same_samples() {
    // The reference: another seed, 2048 samples per pixel.
    let (reference, _) = uniform(2048, 7);
    let (adaptive_film, adaptive_samples) = adaptive(
        512,
        &AdaptiveSettings {
            // The image's RMS error over its mean brightness: at 0.05 the rounds stop near
            // 80 spp on average.
            threshold: 0.05,
            min_spp: 16,
        },
    );
    let pixels = 48 * 48;
    let spp = (adaptive_samples / pixels) as u32;
    assert!(
        (32..400).contains(&spp),
        "the rounds stop between round 0 and the maximum: {spp} spp on average"
    );
    let (uniform_film, uniform_samples) = uniform(spp, 0);
    assert!(uniform_samples <= adaptive_samples);
    let (e_adaptive, e_uniform) = (
        mse(&adaptive_film, &reference),
        mse(&uniform_film, &reference),
    );
    eprintln!("{spp} spp: MSE adaptive {e_adaptive:.4e}, uniform {e_uniform:.4e}");
    assert!(
        e_adaptive < 0.8 * e_uniform,
        "adaptive {e_adaptive:.4e} vs uniform {e_uniform:.4e} at {spp} spp"
    );
}

/// A bright triangle straight in view on black, under the seed scenes' wide filter (a
/// blackmanharris of half-width 4 reaches half a block): a pixel's radiance is the filter's
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
        let planned = (0..round.planned.len())
            .map(|b| if (b % 6 + b / 6) % 2 == 0 { end } else { 16 })
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
            if (x / 8 + y / 8) % 2 == 1 {
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
    // Measured: weighed 0.186 (the 16-sample blocks' noise), plain 291.
    assert!(
        plain > 100.0 * weighed,
        "plain {plain} vs weighed {weighed}"
    );
}
