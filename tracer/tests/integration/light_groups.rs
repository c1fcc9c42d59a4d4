//! Light groups (`LightGroup`): the film keeps each group's light as a layer, the layers add up
//! to the image's light, a layer is what the group's lights alone render, and the image weighs
//! the groups by their settings as LuxRender 1.x's film does; the EXR carries a layer per group.
//! On the exporter-written `scenes/exported/lightgroups.lxs` and small scenes written here.

use glam::{DVec3, Vec3};
use yat_tracer::assets::{FsSource, MemorySource};
use yat_tracer::desc::SceneDesc;
use yat_tracer::film::light_groups::weigh;
use yat_tracer::film::{Film, OutputFile};
use yat_tracer::integrator::Transport;
use yat_tracer::parse::parse_scene;
use yat_tracer::render::RenderOverrides;

use crate::render::render_whole_with;
use crate::util::workspace_root;

fn exported() -> (SceneDesc, FsSource) {
    let path = workspace_root().join("scenes/exported/lightgroups.lxs");
    let source = FsSource::for_main_file(&path);
    let desc = parse_scene("lightgroups.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    (desc, source)
}

fn parse(text: &str) -> (SceneDesc, MemorySource) {
    let mut source = MemorySource::new();
    source.insert("main.lxs", text.as_bytes().into());
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    (desc, source)
}

fn render(desc: &SceneDesc, source: &dyn yat_tracer::assets::AssetSource, spp: u32) -> Film {
    let overrides = RenderOverrides {
        spp: Some(spp),
        ..Default::default()
    };
    render_whole_with(desc, source, &overrides)
}

fn mean(values: &[Vec3]) -> Vec3 {
    values.iter().copied().sum::<Vec3>() / values.len() as f32
}

/// The exporter's scene has its three groups in order, each pixel's groups add up to its
/// light (to float rounding), and each group lights a good part of the image (so the sum is
/// not one group's alone).
#[test]
fn groups_split_the_light_and_add_up_to_it() {
    let (desc, source) = exported();
    let names: Vec<&str> = desc
        .film
        .light_groups
        .groups
        .iter()
        .map(|g| g.name.as_str())
        .collect();
    assert_eq!(names, ["daylight", "ceiling", "fill"]);
    // sunsky is two lights (sun, sky), both daylight; the point light is fill.
    assert_eq!(desc.film.light_groups.of_sources, [0, 0, 2]);
    let lamp = desc.shapes.iter().find_map(|s| s.area_light.as_ref());
    assert_eq!(lamp.map(|l| l.group), Some(1));
    let film = render(&desc, &source, 8);
    assert_eq!(film.frame().layers.light_groups, 3);
    let groups = film.light_group_images(&desc.film.light_groups);
    let total = film.radiance();
    let mut worst: f32 = 0.0;
    for (i, &t) in total.iter().enumerate() {
        let sum: Vec3 = groups.iter().map(|(_, g)| g[i]).sum();
        worst = worst.max(((sum - t).abs() / (t.abs() + Vec3::splat(1e-3))).max_element());
    }
    assert!(
        worst < 1e-4,
        "groups differ from the total by {worst} (relative)"
    );
    let all = mean(&total);
    for (name, light) in &groups {
        let share = mean(light).element_sum() / all.element_sum();
        eprintln!("{name}: {share}");
        assert!(share > 0.05, "{name} has {share} of the light");
    }
}

/// A floor and a ball under the statements `sky` and `lamp` (both may be empty).
fn scene(lamp: &str, sky: &str) -> String {
    format!(
        "Film \"fleximage\" \"integer xresolution\" [32] \"integer yresolution\" [24]\n\
         PixelFilter \"box\" \"float xwidth\" [0.5] \"float ywidth\" [0.5]\n\
         LookAt 0 -3 1  0 0 0.8  0 0 1\n\
         Camera \"perspective\" \"float fov\" [60]\n\
         WorldBegin\n\
         {sky}\n\
         Material \"matte\" \"color Kd\" [0.6 0.6 0.6]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3]\n\
         \x20 \"point P\" [-3 -3 0  3 -3 0  3 3 0  -3 3 0]\n\
         Shape \"sphere\" \"float radius\" [0.5]\n\
         {lamp}\n\
         WorldEnd\n"
    )
}

/// A lamp quad above the ball after the statement `group` (in its own attribute block).
fn lamp(group: &str, gain: f32) -> String {
    format!(
        "AttributeBegin\n{group}\n\
         AreaLightSource \"area\" \"color L\" [4 3 2] \"float gain\" [{gain}]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 2 1 0 3 2]\n\
         \x20 \"point P\" [-0.5 -0.5 2  0.5 -0.5 2  0.5 0.5 2  -0.5 0.5 2]\n\
         AttributeEnd"
    )
}

/// A blue sky after the statement `group`.
fn sky(group: &str) -> String {
    format!("{group}\nLightSource \"infinite\" \"color L\" [0.2 0.3 0.5]")
}

/// A room lit by a lamp quad (group "lamp") and a sky (group "sky"): each group's layer is the
/// image of its light alone (the scene without the other's), within noise, and the image of
/// the lamp's group scaled 3 and the sky's disabled is the lamp scene with its gain tripled.
#[test]
fn a_group_is_its_lights_alone_and_settings_weigh_it() {
    let spp = 256;
    let (both, source) = parse(&scene(
        &lamp("LightGroup \"lamp\"", 1.0),
        &sky("LightGroup \"sky\""),
    ));
    let film = render(&both, &source, spp);
    let groups = film.light_group_images(&both.film.light_groups);
    let alone = |text: String| {
        let (desc, source) = parse(&text);
        assert!(desc.film.light_groups.groups.len() <= 1);
        mean(&render(&desc, &source, spp).radiance())
    };
    let lamp_alone = alone(scene(&lamp("", 1.0), ""));
    // The lamp's quad stays, dark: it hides some of the sky.
    let sky_alone = alone(scene(&lamp("", 0.0), &sky("")));
    for ((name, layer), expected) in groups.iter().zip([sky_alone, lamp_alone]) {
        let ratio = mean(layer) / expected;
        assert!(
            (ratio - Vec3::ONE).abs().max_element() < 0.02,
            "{name}: layer / alone = {ratio}"
        );
    }

    let (weighed, source) = parse(&scene(
        &lamp("LightGroup \"lamp\" \"float scale\" [3]", 1.0),
        &sky("LightGroup \"sky\" \"bool enabled\" [\"false\"]"),
    ));
    let image = render(&weighed, &source, spp).image(&weighed.film);
    let tripled = alone(scene(&lamp("", 3.0), ""));
    let ratio = mean(&image.linear) / tripled;
    assert!(
        (ratio - Vec3::ONE).abs().max_element() < 0.02,
        "lamp x 3, sky off / lamp gain 3 = {ratio}"
    );
}

/// The image is each group's light weighed by its matrix, summed (to f32 rounding): the
/// exporter's ceiling group at scale 1.5 and 3200 K makes the image warmer and brighter there
/// than the plain sum; the EXR holds the weighed image as its RGB and each group's light as
/// rendered in its layer, `lightgroup.<name>.R/G/B`.
#[test]
fn the_image_weighs_the_groups_and_the_exr_keeps_each() {
    let (desc, source) = exported();
    let ceiling = &desc.film.light_groups.groups[1];
    assert_eq!((ceiling.scale, ceiling.temperature), (1.5, 3200.0));
    let film = render(&desc, &source, 8);
    let image = film.image(&desc.film);
    let groups = &image.light_groups;
    let weighings: Vec<_> = desc
        .film
        .light_groups
        .groups
        .iter()
        .map(|g| g.weighing())
        .collect();
    for (i, &pixel) in image.linear.iter().enumerate() {
        let expected: DVec3 = weighings
            .iter()
            .zip(groups)
            .map(|(w, (_, g))| weigh(w, g[i]))
            .sum();
        let error = (pixel.as_dvec3() - expected).abs().max_element();
        assert!(
            error <= 1e-5 * (1.0 + expected.abs().max_element()),
            "pixel {i}"
        );
    }
    // 3200 K is warm: the ceiling's light gains red over blue in the image.
    let plain = mean(&film.radiance());
    let weighed = mean(&image.linear);
    assert!(
        weighed.x / weighed.z > 1.05 * plain.x / plain.z && weighed.y > plain.y,
        "plain {plain}, weighed {weighed}"
    );

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("groups.exr");
    let exr = desc
        .film
        .outputs
        .files(false)
        .into_iter()
        .find(|f| matches!(f, OutputFile::Exr(_)))
        .expect("the scene writes an EXR");
    image.write(&exr, &path).unwrap();
    let channels = exr_channels(&path);
    let channel = |name: &str| {
        &channels
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("no channel {name} among {:?}", names(&channels)))
            .1
    };
    let (w, h) = (image.width as usize, image.height as usize);
    for (name, light) in groups {
        for (c, letter) in ["R", "G", "B"].into_iter().enumerate() {
            let values = channel(&format!("lightgroup.{name}.{letter}"));
            assert_eq!(values.len(), w * h);
            assert!(
                values.iter().zip(light).all(|(&v, l)| v == l[c]),
                "{name}.{letter}"
            );
        }
    }
    let red = channel("R");
    assert!(red.iter().zip(&image.linear).all(|(&v, l)| v == l.x));
}

fn names(channels: &[(String, Vec<f32>)]) -> Vec<&str> {
    channels.iter().map(|(n, _)| n.as_str()).collect()
}

/// The channels of an EXR, read back: name -> values, rows top to bottom.
fn exr_channels(path: &std::path::Path) -> Vec<(String, Vec<f32>)> {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_file(path)
        .unwrap();
    image
        .layer_data
        .iter()
        .flat_map(|layer| {
            let prefix = layer
                .attributes
                .layer_name
                .as_ref()
                .map(|n| format!("{n}."))
                .unwrap_or_default();
            layer.channel_data.list.iter().map(move |c| {
                let values = c.sample_data.values_as_f32().collect();
                (format!("{prefix}{}", c.name), values)
            })
        })
        .collect()
}

/// LuxRender's context: a light outside every group is in "default", made at its first light;
/// a group lasts to the end of its attribute block; area lights take the group of their
/// shape's statement; a group named again is the same group, its settings changed only where
/// given; more groups than YAT keeps is an error naming the statement.
#[test]
fn groups_follow_luxrenders_graphics_state() {
    let (desc, _) = parse(
        "WorldBegin\n\
         LightSource \"point\" \"point from\" [0 0 1]\n\
         AttributeBegin\n\
         LightGroup \"a\" \"float scale\" [2]\n\
         LightSource \"point\" \"point from\" [0 0 2]\n\
         AreaLightSource \"area\" \"color L\" [1 1 1]\n\
         LightGroup \"b\"\n\
         Shape \"sphere\"\n\
         LightGroup \"a\" \"float temperature\" [5000]\n\
         AttributeEnd\n\
         LightSource \"point\" \"point from\" [0 0 3]\n\
         WorldEnd\n",
    );
    let groups = &desc.film.light_groups;
    let names: Vec<&str> = groups.groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["default", "a", "b"]);
    assert_eq!(groups.of_sources, [0, 1, 0]);
    assert_eq!(desc.shapes[0].area_light.as_ref().unwrap().group, 2);
    assert_eq!(
        (groups.groups[1].scale, groups.groups[1].temperature),
        (2.0, 5000.0)
    );

    let many: String = (0..7)
        .map(|i| format!("LightGroup \"g{i}\"\nLightSource \"point\"\n"))
        .collect();
    let mut source = MemorySource::new();
    source.insert(
        "main.lxs",
        format!("WorldBegin\n{many}WorldEnd\n").into_bytes().into(),
    );
    let error = parse_scene("main.lxs", &source).unwrap_err().to_string();
    assert!(
        error.contains("main.lxs:14:1") && error.contains("at most 6"),
        "{error}"
    );
}

/// Under bidirectional transport each strategy's light goes to the group of the light its
/// path starts at, and the light-tracing splats carry each group's share in a plane of their
/// own: the groups add up to the image, splats included, and each group's layer is the path
/// tracer's within noise.
#[test]
fn bidirectional_renders_keep_the_groups_apart_too() {
    let (desc, source) = parse(&scene(
        &lamp("LightGroup \"lamp\"", 1.0),
        &sky("LightGroup \"sky\""),
    ));
    let render = |transport| {
        let overrides = RenderOverrides {
            spp: Some(256),
            transport,
            ..Default::default()
        };
        render_whole_with(&desc, &source, &overrides)
    };
    let bidirectional = render(Some(Transport::Bidirectional));
    assert!(bidirectional.splats().is_some());
    assert_eq!(bidirectional.frame().layers.light_groups, 2);
    let groups = bidirectional.light_group_images(&desc.film.light_groups);
    for (i, &total) in bidirectional.radiance().iter().enumerate() {
        let sum: Vec3 = groups.iter().map(|(_, g)| g[i]).sum();
        let error = ((sum - total).abs() / (total.abs() + Vec3::splat(1e-3))).max_element();
        assert!(error < 1e-4, "pixel {i}: groups {sum}, image {total}");
    }
    let path = render(Some(Transport::Path));
    let path_groups = path.light_group_images(&desc.film.light_groups);
    for ((name, light), (_, traced)) in groups.iter().zip(&path_groups) {
        let ratio = mean(light) / mean(traced);
        assert!(
            (ratio - Vec3::ONE).abs().max_element() < 0.03,
            "{name}: bidirectional / path = {ratio}"
        );
    }
}
