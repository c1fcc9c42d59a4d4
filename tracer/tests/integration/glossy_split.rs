//! Paths split at their first glossy vertex that may see a lamp (`GLOSSY_SPLIT` BSDF samples
//! for the lamps it sees directly, in `tracer/src/integrator/glossy_split.rs`): the estimate
//! keeps the one-sample path tracer's mean and its highlights are less noisy.

use glam::Vec3;
use yat_tracer::integrator::PathScene;

use super::estimates::{self, seed_difference};

const SIZE: u32 = 40;

/// The camera of [`estimates::looking_down`] with a path integrator of depth 3, splitting or
/// not.
fn camera(split: bool) -> String {
    let integrator = format!("\"integer maxdepth\" [3] \"bool glossysplit\" [\"{split}\"]");
    estimates::looking_down(SIZE, &integrator)
}

/// A grey metal with GGX roughness `alpha`.
fn metal(alpha: f32) -> String {
    format!(
        "Material \"metal2\" \"color fresnel\" [0.8 0.8 0.8] \
         \"float uroughness\" [{alpha}] \"float vroughness\" [{alpha}]"
    )
}

/// The camera looks down on a floor whose left half is a rough metal (alpha 0.05) and right
/// half grey matte. A lamp (null material, as LuxBlend exports them: the camera sees through
/// its back) hangs over the left, where the metal reflects it to the camera, and the matte half
/// sees its highlight on the metal too; a dim sky lights everything. Depth 3.
fn scene(split: bool) -> String {
    format!(
        "{}\
         LightSource \"infinite\" \"color L\" [0.1 0.1 0.1]\n\
         AttributeBegin\n\
         Material \"metal2\" \"color fresnel\" [0.8 0.8 0.8] \"float uroughness\" [0.05] \"float vroughness\" [0.05]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
           \"point P\" [-3 -3 0  0 -3 0  0 3 0  -3 3 0]\n\
         AttributeEnd\n\
         AttributeBegin\n\
         Material \"matte\" \"color Kd\" [0.5 0.5 0.5]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
           \"point P\" [0 -3 0  3 -3 0  3 3 0  0 3 0]\n\
         AttributeEnd\n\
         AttributeBegin\n\
         Material \"null\"\n\
         AreaLightSource \"area\" \"color L\" [20 20 20] \"float power\" [0]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
           \"point P\" [-1 -0.4 1.5  -1 0.4 1.5  -0.3 0.4 1.5  -0.3 -0.4 1.5]\n\
         AttributeEnd\n\
         WorldEnd\n",
        camera(split)
    )
}

fn render(text: &str, spp: u32, seed: u64) -> Vec<Vec3> {
    let (scene, settings) = estimates::build(text, SIZE, spp, seed);
    estimates::radiance(&scene, &settings)
}

/// Both sides of the MIS weights count the split vertex's BSDF samples: a count missing on
/// either side moves the mean.
#[test]
fn splitting_keeps_the_mean() {
    estimates::assert_same_mean(|split, seed| render(&scene(split), 512, seed));
}

/// The highlight is where one BSDF sample finds the lamp or misses it; eight stratified ones
/// see it far more evenly.
#[test]
fn splitting_cuts_the_noise_of_highlights() {
    let noise = |split| seed_difference(|seed| render(&scene(split), 16, seed));
    let (noise_plain, noise_split) = (noise(false), noise(true));
    assert!(
        noise_split * 5.0 < noise_plain,
        "noise split {noise_split}, one sample {noise_plain}"
    );
}

/// A scene splits only with lamps and metals, and without what would make a split sample's way
/// differ from the path's: volumes, a mix that can turn into `null`, a layered material.
#[test]
fn only_scenes_with_lamps_and_metals_split() {
    let splits = |text: &str| estimates::build(text, SIZE, 1, 0).0.glossy_split();
    let base = scene(true);
    assert!(splits(&base));
    assert!(!splits(&scene(false)));
    let world_end = base.rfind("WorldEnd").unwrap();
    let with = |extra: &str| format!("{}{extra}\nWorldEnd\n", &base[..world_end]);
    assert!(splits(&with(
        "MakeNamedMaterial \"paint\" \"string type\" [\"matte\"]"
    )));
    assert!(!splits(&with(
        "MakeNamedMaterial \"hole\" \"string type\" [\"null\"]\n\
         MakeNamedMaterial \"paint\" \"string type\" [\"matte\"]\n\
         MakeNamedMaterial \"holey\" \"string type\" [\"mix\"] \"string namedmaterial1\" [\"paint\"] \
         \"string namedmaterial2\" [\"hole\"]"
    )));
    assert!(!splits(&with(
        "MakeNamedMaterial \"paint\" \"string type\" [\"matte\"]\n\
         MakeNamedMaterial \"decal\" \"string type\" [\"layered\"] \"string namedmaterial1\" [\"paint\"] \
         \"float opacity1\" [0.5]"
    )));
    assert!(!splits(&with(
        "MakeNamedVolume \"smoke\" \"homogeneous\" \"color sigma_s\" [1 1 1]\n\
         Interior \"smoke\"\nShape \"sphere\" \"float radius\" [0.2]"
    )));
    let no_metal = base.replace("\"metal2\" \"color fresnel\"", "\"matte\" \"color Kd\"");
    assert!(!splits(&no_metal.replace(
        " \"float uroughness\" [0.05] \"float vroughness\" [0.05]",
        ""
    )));
    let no_lamp = base.replace(
        "AreaLightSource \"area\" \"color L\" [20 20 20] \"float power\" [0]\n",
        "",
    );
    assert!(!splits(&no_lamp));
}

/// The camera of [`scene`] over a rough metal floor (alpha 0.05); above the camera a matte
/// ceiling, lit by a lamp facing up from outside the view. The floor shows the ceiling's bright
/// patch blurred, and nothing else: every path splits at the floor (its lobe holds the lamp,
/// whose back it sees) and goes on to the ceiling, where its light sample finds the lamp. All
/// the light comes through the path's own BSDF sample, none through the split's. Depth 3.
fn ceiling_scene(split: bool) -> String {
    let lamp = format!("Material \"null\"\n{}", estimates::LAMP);
    [
        camera(split),
        estimates::quad(&metal(0.05), estimates::FLOOR),
        estimates::quad(&lamp, ["1 -0.3 4", "1.6 -0.3 4", "1.6 0.3 4", "1 0.3 4"]),
        estimates::quad(
            estimates::MATTE_FLOOR,
            ["-4 -4 6", "-4 4 6", "4 4 6", "4 -4 6"],
        ),
        "WorldEnd\n".to_owned(),
    ]
    .concat()
}

/// A split vertex's path goes on with the vertex's own numbers: the split's samples are
/// stratified only together (each one's values over a pixel's samples lie in one strip of the
/// lobe), so a path going on with one of them saw the same strip of the ceiling in every sample
/// of a pixel, and its noise hardly fell with more samples.
#[test]
fn a_split_vertex_path_sees_the_whole_lobe() {
    assert!(estimates::build(&ceiling_scene(true), SIZE, 1, 0)
        .0
        .glossy_split());
    let noise = |spp| seed_difference(|seed| render(&ceiling_scene(true), spp, seed));
    // About 4 or more where a pixel's paths spread over the whole lobe (1.15 when they did not).
    let ratio = noise(8) / noise(32);
    assert!(ratio > 2.5, "noise at 8 spp / at 32 spp: {ratio}");
}

/// The light a split vertex's path finds beyond it keeps the one-sample path's mean.
#[test]
fn a_split_vertex_path_keeps_the_mean() {
    estimates::assert_same_mean(|split, seed| render(&ceiling_scene(split), 512, seed));
}

/// An equirectangular sky, black but for its top row: a bright cap of 5.6 degrees around the
/// zenith, about as wide as a glossy lobe, so the light samples that find it are about as
/// likely as the lobe's BSDF samples.
fn zenith_cap_map() -> Vec<u8> {
    let sky = image::Rgb32FImage::from_fn(64, 32, |_, y| {
        image::Rgb([if y == 0 { 20.0 } else { 0.0 }; 3])
    });
    let mut bytes = std::io::Cursor::new(Vec::new());
    image::DynamicImage::from(sky)
        .write_to(&mut bytes, image::ImageFormat::Hdr)
        .unwrap();
    bytes.into_inner()
}

/// A metal floor (alpha 0.08) under that sky and a small null lamp beside the zenith, inside
/// the lobes of the floor's middle, which split and reflect the cap.
fn cap_scene(split: bool) -> String {
    let lamp = format!("Material \"null\"\n{}", estimates::LAMP);
    [
        camera(split),
        "LightSource \"infinite\" \"string mapname\" [\"sky.hdr\"]\n".to_owned(),
        estimates::quad(&metal(0.08), estimates::FLOOR),
        estimates::quad(
            &lamp,
            ["0.3 -0.15 2", "0.3 0.15 2", "0.6 0.15 2", "0.6 -0.15 2"],
        ),
        "WorldEnd\n".to_owned(),
    ]
    .concat()
}

/// A split vertex's light sample of an environment map is weighed against the path's one BSDF
/// sample, which finds the environment (the split's eight look for lamps only): with the eight
/// counted there instead, the cap's light goes missing from the metal.
#[test]
fn splitting_keeps_the_mean_of_the_sky_in_the_lobe() {
    let sky = zenith_cap_map();
    estimates::assert_same_mean(|split, seed| {
        let files: [(&str, &[u8]); 1] = [("sky.hdr", &sky)];
        let (scene, settings) = estimates::build_with(&cap_scene(split), &files, SIZE, 512, seed);
        estimates::radiance(&scene, &settings)
    });
}
