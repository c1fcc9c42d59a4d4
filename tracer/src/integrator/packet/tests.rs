use crate::integrator::PathScene;
use std::sync::atomic::AtomicBool;

use crate::assets::MemorySource;
use crate::film::SampleBuffer;
use crate::lanes::tests::on_every_lane_type;
use crate::lanes::Lanes;
use crate::lanes::OnLanes;
use crate::parse::parse_scene;
use crate::render::{plan_units, RenderScene, RenderSettings, WorkUnit};

/// A depth-of-field scene of our own: a thin lens, a checkered Lambert floor, a red
/// Lambert sphere; what packets shade one lane at a time: a glass sphere, a rough
/// (Oren-Nayar) wall, a flat mirror with the lamp's image, a gold sphere (whose glossy
/// vertices split paths, which leave the packet); and what lanes leave packets for: a null
/// lamp seen directly, the open sky.
const SCENE: &str = r#"LookAt 0 -4 1.2  0 0 0.6  0 0 1
Camera "perspective" "float fov" [50] "float lensradius" [0.1] "float focaldistance" [3.5]
Film "fleximage" "integer xresolution" [24] "integer yresolution" [16]
PixelFilter "gaussian"
SurfaceIntegrator "path" "integer maxdepth" [6]
WorldBegin
Texture "checks" "color" "checkerboard" "float uscale" [6] "float vscale" [6] "color tex1" [0.8 0.8 0.8] "color tex2" [0.1 0.1 0.1]
AttributeBegin
Material "matte" "texture Kd" ["checks"]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-3 -3 0 3 -3 0 3 3 0 -3 3 0] "float uv" [0 0 1 0 1 1 0 1]
AttributeEnd
AttributeBegin
Material "matte" "color Kd" [0.5 0.5 0.5] "float sigma" [30]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-3 2 0 3 2 0 3 2 3 -3 2 3]
AttributeEnd
AttributeBegin
Material "matte" "color Kd" [0.7 0.2 0.2]
Translate -0.6 0 0.5
Shape "sphere" "float radius" [0.5]
AttributeEnd
AttributeBegin
Material "glass"
Translate 0.7 -0.4 0.4
Shape "sphere" "float radius" [0.4]
AttributeEnd
AttributeBegin
Material "mirror"
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-2.5 -2 0 -2.5 2 0 -2.5 2 2.5 -2.5 -2 2.5]
AttributeEnd
AttributeBegin
Material "metal" "string name" ["gold"] "float uroughness" [0.05] "float vroughness" [0.05]
Translate 0.3 0.9 0.35
Shape "sphere" "float radius" [0.35]
AttributeEnd
AttributeBegin
Material "null"
AreaLightSource "area" "color L" [6 6 6] "float power" [0]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-0.5 -0.5 2 -0.5 0.5 2 0.5 0.5 2 0.5 -0.5 2]
AttributeEnd
"#;

/// A light that makes the lamp's tables go (the light's choice and point one lane at a
/// time).
const POINT: &str = r#"LightSource "point" "point from" [1 -1 2.5] "color L" [0.5 0.5 0.5]"#;

/// The scene with `light` beside the lamp (its tables are sampled in lanes when there is
/// none).
fn scene(spp: u32, branches: usize, light: &str) -> (RenderScene, RenderSettings) {
    let mut source = MemorySource::new();
    let text = format!("{SCENE}{light}\nWorldEnd\n");
    source.insert("main.lxs", text.as_bytes().into());
    let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let settings = RenderSettings {
        width: 24,
        height: 16,
        spp,
        max_depth: desc.integrator.max_depth,
        seed: 3,
        latlong: Default::default(),
        transport: Default::default(),
        aovs: Default::default(),
    };
    let scene = RenderScene::build(&desc, &source, &settings).expect("scene builds");
    assert!(super::covers(&scene), "packets cover the scene");
    assert!(scene.glossy_split(), "the gold sphere splits paths");
    assert!(
        scene.lights().has_mirror_images(),
        "the mirror shows the lamp"
    );
    assert_eq!(
        scene.lights().triangle_lamps().is_some(),
        light.is_empty(),
        "lamp tables with {light:?}"
    );
    (scene.with_first_vertex_branches(branches), settings)
}

/// Every unit of a uniform render (72 samples a pixel, 9 a unit: a packet and a sample
/// left over) and of an adaptive round (nested samples 16 to 48 in blocks of the floor,
/// the spheres and the wall) renders to the same buffer bytes and counts in packets of
/// every lane type as one sample at a time, with one continuation per camera path and with
/// three, with the lamp sampled from its tables in lanes and (beside a point light) one
/// lane at a time.
fn packets_render_the_scalar_bytes<L: Lanes>() {
    let never = AtomicBool::new(false);
    for (branches, light) in [(1, ""), (3, ""), (1, POINT), (3, POINT)] {
        let (scene, settings) = scene(72, branches, light);
        let adaptive = WorkUnit {
            index: 0,
            x0: 0,
            y0: 0,
            x1: 16,
            y1: 16,
            sample_start: 16,
            sample_end: 48,
            // Blocks (1, 0), and (1, 2), (2, 2), (1, 3), (2, 3) on the floor and spheres.
            mask: Some(0x0606_0002),
        };
        let mut rays = 0;
        for unit in plan_units(&settings).iter().chain([&adaptive]) {
            let (one, one_stats) = scene.render_unit_in::<f32>(unit, &never).unwrap();
            let (lanes, lane_stats) = scene.render_unit_in::<L>(unit, &never).unwrap();
            let at = format!(
                "unit {unit:?}, {branches} continuations, light {light:?}, {} lanes",
                L::N
            );
            assert_eq!(lane_stats, one_stats, "{at}");
            assert_eq!(
                bits(lanes.rgb.as_flattened()),
                bits(one.rgb.as_flattened()),
                "{at}"
            );
            assert_eq!(bits(&lanes.weight), bits(&one.weight), "{at}");
            let half = |b: &SampleBuffer| bits(b.half_rgb.as_flattened());
            assert_eq!(half(&lanes), half(&one), "{at}");
            rays += one_stats.rays;
        }
        assert!(rays > 0);
    }
}

fn bits(values: &[f32]) -> Vec<u32> {
    values.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn packets_render_what_one_path_at_a_time_renders() {
    struct Renders;
    impl OnLanes for Renders {
        type Output = ();
        fn run<L: Lanes>(&self) {
            packets_render_the_scalar_bytes::<L>();
        }
    }
    on_every_lane_type(&Renders);
}
