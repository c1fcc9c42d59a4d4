//! Camera paths that branch at their first broad vertex (`integrator::MAX_BRANCHES`,
//! `render::branching`): the estimate keeps the single path's mean, lamps seen directly and
//! through a mirror included, its noise drops where light comes through the first bounce, and
//! the pilot gives the seed scenes the counts measured to pay.

use glam::Vec3;
use yat_tracer::assets::FsSource;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::{branching, RenderOverrides, RenderScene, RenderSettings};

use super::estimates::{self, seed_difference, FLOOR, LAMP, MATTE_FLOOR, MIRROR};
use crate::util::seed_scenes;

const SIZE: u32 = 40;

/// A grey floor, a white wall at x = 1.2 facing it, a mirror wall at x = -1.2 (lamp images on)
/// and a square lamp: above the floor facing down, the floor sees it directly, through the
/// mirror and off the wall; `toward_wall`, upright and facing the wall, the floor's light is
/// nearly all what the wall sends back. Depth 3.
fn scene(toward_wall: bool) -> String {
    let lamp = if toward_wall {
        ["0.9 -0.4 0.3", "0.9 0.4 0.3", "0.9 0.4 1.1", "0.9 -0.4 1.1"]
    } else {
        ["0.3 -0.4 0.8", "0.3 0.4 0.8", "1.0 0.4 0.8", "1.0 -0.4 0.8"]
    };
    let integrator = "\"integer maxdepth\" [3] \"bool mirrorimages\" [\"true\"]";
    let white = "Material \"matte\" \"color Kd\" [0.8 0.8 0.8]";
    [
        estimates::looking_down(SIZE, integrator),
        estimates::quad(MATTE_FLOOR, FLOOR),
        estimates::quad(white, ["1.2 -3 0", "1.2 3 0", "1.2 3 3", "1.2 -3 3"]),
        estimates::quad(MIRROR, ["-1.2 -3 0", "-1.2 -3 3", "-1.2 3 3", "-1.2 3 0"]),
        estimates::quad(LAMP, lamp),
        "WorldEnd\n".into(),
    ]
    .concat()
}

fn render(toward_wall: bool, branches: usize, spp: u32, seed: u64) -> Vec<Vec3> {
    let (scene, settings) = estimates::build(&scene(toward_wall), SIZE, spp, seed);
    let scene = scene.with_first_vertex_branches(branches);
    estimates::radiance(&scene, &settings)
}

/// Three continuations, each weighed by a third and counted three times against the light
/// sample (directly and through the mirror), estimate what one path does.
#[test]
fn branching_keeps_the_mean() {
    estimates::assert_same_mean(|branched, seed| {
        render(false, if branched { 3 } else { 1 }, 256, seed)
    });
}

/// Where the floor's light comes off the wall, three continuations per camera sample take much
/// of its noise away.
#[test]
fn branching_cuts_the_noise_of_the_first_bounce() {
    let noise = |branches| seed_difference(|seed| render(true, branches, 16, seed));
    let (one, three) = (noise(1), noise(3));
    println!("noise with 3 continuations {three}, with 1 {one}");
    assert!(
        three < 0.7 * one,
        "noise with 3 continuations {three}, with 1 {one}"
    );
}

/// The pilot's errors of one and two continuations say what two do to a render's noise where
/// the light comes off the wall, a tenth either way allowed for the noise of both (the pilot's
/// ratio over four seeds, 0.58; the renders' over eight pairs, 0.61).
#[test]
fn the_pilot_measures_the_noise_of_two_continuations() {
    let predicted = (1..=4)
        .map(|seed| {
            let (scene, _) = estimates::build(&scene(true), SIZE, 4096, seed);
            let f = branching::measure(&scene).expect("the render is long enough for a pilot");
            f.error[1] / f.error[0]
        })
        .sum::<f64>()
        / 4.0;
    let noise = |branches| -> f64 {
        (0..8)
            .map(|pair| seed_difference(|seed| render(true, branches, 16, 2 * pair + seed)))
            .sum()
    };
    let measured = noise(2) / noise(1);
    println!("noise with 2 continuations over 1: measured {measured}, predicted {predicted}");
    assert!(
        (0.9 * predicted..1.1 * predicted).contains(&measured),
        "noise with 2 continuations over 1: measured {measured}, predicted {predicted}"
    );
}

/// The pilot on a seed scene at a render long enough to run it (240x135, 512 spp).
fn chosen(scene: &str) -> Option<usize> {
    let path = seed_scenes()?.join(scene);
    let source = FsSource::for_main_file(&path);
    let name = path.file_name()?.to_str()?;
    let desc = parse_scene(name, &source).expect("seed scene parses");
    let settings = RenderSettings::resolve(
        &desc,
        &RenderOverrides {
            spp: Some(512),
            max_depth: Some(10),
            resolution: Some((240, 135)),
            ..Default::default()
        },
    );
    let scene = RenderScene::build(&desc, &source, &settings).expect("seed scene builds");
    Some(scene.first_vertex_branches())
}

/// Measured (480x270, 16 spp, MSE x time against one continuation): depth of field 1.25x with
/// two, 1.30x with three; Captain Falcon 1.17x with two; Mario 0.98x with two (its noise is
/// caustics its glossy vertices split for). The pilot must find all three.
#[test]
fn the_pilot_branches_depth_of_field_and_falcon_not_mario() {
    let Some(dof) = chosen("DepthOfField/depth-of-field-high.lxs") else {
        return;
    };
    assert!(dof >= 2, "depth of field: {dof} continuations");
    let falcon = chosen("CaptainFalcon/captainfalcon.lxs").expect("the seed scenes are there");
    assert_eq!(falcon, 2, "Captain Falcon");
    let mario = chosen("MetalMario/metal-mario-bg1.lxs").expect("the seed scenes are there");
    assert_eq!(mario, 1, "Mario");
}

/// The pilot's figures are the same bytes whatever the threads it runs on: every node that
/// builds the scene chooses the same count.
#[test]
fn the_pilot_is_the_same_on_any_number_of_threads() {
    // 40 x 40 x 4096 samples: a render long enough for a pilot of 1024 pixels.
    let (scene, _) = estimates::build(&scene(true), SIZE, 4096, 1);
    let on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| branching::measure(&scene))
    };
    let one = on(1).expect("the render is long enough for a pilot");
    assert_eq!(on(3), Some(one));
    assert!(one.error[0] > 0.0 && one.rays[1] > one.rays[0], "{one:?}");
    assert_eq!(scene.first_vertex_branches(), one.best());
}

/// A render too short to spare a pilot (40 x 40 x 64 samples, where a pilot of 1024 pixels of
/// 16 samples, four renders, needs 25 times their camera samples) takes none.
#[test]
fn a_short_render_takes_no_pilot() {
    let (scene, _) = estimates::build(&scene(true), SIZE, 64, 1);
    assert_eq!(branching::measure(&scene), None);
    assert_eq!(scene.first_vertex_branches(), 1);
}
