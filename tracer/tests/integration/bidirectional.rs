//! Bidirectional path tracing against what it must equal: the path tracer's image where both
//! can render the light, and the analytic irradiance of a point light seen in a mirror, which
//! only light tracing carries (a point light reflected by a mirror onto a floor: no camera path
//! finds a point light behind a mirror).

use crate::statistics::correlation;
use glam::Vec3;
use yat_tracer::integrator::Transport;

use super::estimates;

const SIZE: u32 = 24;

fn mean(image: &[Vec3]) -> Vec3 {
    image.iter().copied().sum::<Vec3>() / image.len() as f32
}

fn render(text: &str, spp: u32, seed: u64, transport: Transport) -> Vec<Vec3> {
    let (scene, settings) = estimates::build_for(text, &[], SIZE, spp, seed, transport);
    estimates::radiance(&scene, &settings)
}

/// A grey room (floor, walls and ceiling of matte quads) lit by a small area lamp under its
/// ceiling, seen from inside: every path length matters, and every strategy can make them.
pub(super) fn room(integrator: &str) -> String {
    let wall = "Material \"matte\" \"color Kd\" [0.6 0.6 0.6]";
    let red = "Material \"matte\" \"color Kd\" [0.7 0.2 0.2]";
    let lamp = "AreaLightSource \"area\" \"color L\" [8 8 8] \"float power\" [0]";
    let quads = [
        (wall, ["-1 -1 0", "1 -1 0", "1 1 0", "-1 1 0"]),
        (wall, ["-1 -1 2", "-1 1 2", "1 1 2", "1 -1 2"]),
        (red, ["-1 -1 0", "-1 1 0", "-1 1 2", "-1 -1 2"]),
        (wall, ["1 -1 0", "1 -1 2", "1 1 2", "1 1 0"]),
        (wall, ["-1 1 0", "1 1 0", "1 1 2", "-1 1 2"]),
        (
            lamp,
            [
                "-0.3 -0.3 1.99",
                "-0.3 0.3 1.99",
                "0.3 0.3 1.99",
                "0.3 -0.3 1.99",
            ],
        ),
    ];
    let mut text = format!(
        "LookAt 0 -0.95 1  0 1 1  0 0 1\n\
         Camera \"perspective\" \"float fov\" [70]\n\
         Film \"fleximage\" \"integer xresolution\" [{SIZE}] \"integer yresolution\" [{SIZE}]\n\
         PixelFilter \"gaussian\"\n\
         SurfaceIntegrator {integrator}\n\
         WorldBegin\n"
    );
    for (material, points) in quads {
        text += &estimates::quad(material, points);
    }
    text + "WorldEnd\n"
}

/// `scene` (a room's text) filled with a homogeneous fog of scattering `sigma_s` per unit,
/// slightly coloured by its absorption and scattering forward: both sides of every shape and
/// the camera (the Exterior current at WorldEnd) are in it.
fn in_fog(scene: &str, sigma_s: f32) -> String {
    let fog = format!(
        "VolumeIntegrator \"multi\"\nWorldBegin\n\
         MakeNamedVolume \"fog\" \"homogeneous\" \"float fresnel\" [1]\n\
         \"color sigma_a\" [0.02 0.05 0.1] \"color sigma_s\" [{sigma_s} {sigma_s} {sigma_s}] \"float g\" [0.4]\n\
         Interior \"fog\"\n\
         Exterior \"fog\"\n"
    );
    scene.replacen("WorldBegin\n", &fog, 1)
}

/// The room lit by a point light (`"point from"` `at`) instead of its lamp.
fn point_lit_room(integrator: &str, at: &str) -> String {
    let lamp = "AttributeBegin\nAreaLightSource";
    let text = room(integrator);
    let start = text.find(lamp).expect("the room has a lamp");
    let end = start
        + text[start..]
            .find("AttributeEnd\n")
            .expect("its block ends")
        + 13;
    format!(
        "{}LightSource \"point\" \"point from\" [{at}] \"color L\" [2 2 2]\n{}",
        &text[..start],
        &text[end..]
    )
}

/// The correlation of `a`'s and `b`'s pixels' brightness.
fn brightness_correlation(a: &[Vec3], b: &[Vec3]) -> f64 {
    let brightness =
        |v: &[Vec3]| -> Vec<f64> { v.iter().map(|p| f64::from(p.x + p.y + p.z)).collect() };
    correlation(&brightness(a), &brightness(b))
}

/// `scene` (a scene's text for a given SurfaceIntegrator) rendered bidirectionally with 3
/// scattering vertices a subpath and path traced at depth 6, which make the same paths, at
/// `spp`: asserts their means agree within `tolerance` a channel, and returns (path,
/// bidirectional).
fn assert_means_agree(
    scene: impl Fn(&str) -> String,
    spp: u32,
    tolerance: f32,
) -> (Vec<Vec3>, Vec<Vec3>) {
    let bidir = scene("\"bidirectional\" \"integer eyedepth\" [3] \"integer lightdepth\" [3]");
    let path = scene("\"path\" \"integer maxdepth\" [6]");
    let path = render(&path, spp, 1, Transport::Path);
    let bidir = render(&bidir, spp, 1, Transport::Bidirectional);
    let (p, b) = (mean(&path), mean(&bidir));
    for c in 0..3 {
        assert!(
            (b[c] / p[c] - 1.0).abs() < tolerance,
            "bidirectional {b}, path {p}"
        );
    }
    (path, bidir)
}

/// The room's image is the path tracer's: bidirectional subpaths of 3 scattering vertices
/// each make every path of up to 6, as a path tracer of depth 6 does. The means agree within
/// 1% (measured: 0.1%), and the pixels correlate.
#[test]
fn a_room_renders_as_the_path_tracer_renders_it() {
    let (path, bidir) = assert_means_agree(room, 1024, 0.01);
    let correlation = brightness_correlation(&path, &bidir);
    assert!(correlation > 0.99, "correlation {correlation}");
}

/// The room's floor made of LuxRender's `scatter` (f = R phase / |cos_i|: not reciprocal):
/// light subpaths scatter by its adjoint, and the image is the path tracer's (means within 1%;
/// scattering importance by f itself made the seed-like `scenes/materials2`'s scatter sphere up
/// to 10% too bright).
#[test]
fn a_scatter_floor_renders_as_the_path_tracer_renders_it() {
    let scatter_floor = |integrator: &str| {
        room(integrator).replacen(
            "Material \"matte\" \"color Kd\" [0.6 0.6 0.6]",
            "Material \"scatter\" \"color Kd\" [0.6 0.6 0.6] \"color g\" [0.3 0.3 0.3]",
            1,
        )
    };
    assert_means_agree(scatter_floor, 512, 0.01);
}

/// The room's lamp made of `null` (a LuxBlend habit: the emitter is a light, not a surface)
/// and seen from below: camera paths cross it, and the strategy of a camera path ending on it
/// is taken as they cross. The image is the path tracer's (means within 1%; without that
/// strategy the lamp is black and the room half as bright).
#[test]
fn a_lamp_of_null_material_is_seen_and_lights_the_room() {
    let null_lamp = |integrator: &str| {
        room(integrator)
            .replace("LookAt 0 -0.95 1  0 1 1", "LookAt 0 -0.95 0.6  0 0.3 1.99")
            .replace("AreaLightSource", "Material \"null\"\nAreaLightSource")
    };
    let (path, _) = assert_means_agree(null_lamp, 256, 0.01);
    let brightest = path.iter().map(|v| v.x).fold(0.0, f32::max);
    assert!(brightest > 7.0, "the camera sees the lamp: {brightest}");
}

/// A ball on an infinite plane under a uniform sky (the seed's benchmark scenes): light from
/// infinity enters through a disc as wide as the ball's bounding sphere, so the plane beyond
/// it is lit by camera strategies alone, and their weights must say so. The image is the path
/// tracer's (means within 1%; weighing the plane beyond the disc as light subpaths could reach
/// it darkens it by a fifth).
#[test]
fn an_infinite_plane_under_the_sky_renders_as_the_path_tracer_renders_it() {
    let scene = |integrator: &str| {
        format!(
            "LookAt 0 -4 1  0 0 0.4  0 0 1\n\
             Camera \"perspective\" \"float fov\" [60]\n\
             Film \"fleximage\" \"integer xresolution\" [{SIZE}] \"integer yresolution\" [{SIZE}]\n\
             PixelFilter \"box\"\n\
             SurfaceIntegrator {integrator}\n\
             WorldBegin\n\
             LightSource \"infinite\" \"color L\" [0.5 0.5 0.5]\n\
             AttributeBegin\n\
             Material \"matte\" \"color Kd\" [0.6 0.6 0.6]\n\
             Shape \"plane\" \"normal N\" [0 0 1]\n\
             AttributeEnd\n\
             AttributeBegin\n\
             Translate 0 0 0.5\n\
             Material \"matte\" \"color Kd\" [0.8 0.3 0.2]\n\
             Shape \"sphere\" \"float radius\" [0.5]\n\
             AttributeEnd\n\
             WorldEnd\n"
        )
    };
    assert_means_agree(scene, 256, 0.01);
}

/// A point light at `LIGHT_Z` between a grey floor (Kd `KD`) and a mirror ceiling (Kr `KR`) at
/// `MIRROR_Z`, seen from (0, 0, `camera_z`) looking straight up or down at `look_z`.
pub(super) fn point_light_under_mirror(integrator: &str, camera_z: f64, look_z: f64) -> String {
    let (z, m, i) = (LIGHT_Z, MIRROR_Z, INTENSITY);
    format!(
        "LookAt 0 0 {camera_z}  0 0 {look_z}  0 1 0\n\
         Camera \"perspective\" \"float fov\" [50]\n\
         Film \"fleximage\" \"integer xresolution\" [{SIZE}] \"integer yresolution\" [{SIZE}]\n\
         PixelFilter \"box\"\n\
         SurfaceIntegrator {integrator}\n\
         WorldBegin\n\
         LightSource \"point\" \"point from\" [0 0 {z}] \"color L\" [{i} {i} {i}]\n\
         {}{}WorldEnd\n",
        estimates::quad(
            &format!("Material \"matte\" \"color Kd\" [{KD} {KD} {KD}]"),
            ["-20 -20 0", "20 -20 0", "20 20 0", "-20 20 0"]
        ),
        estimates::quad(
            &format!("Material \"mirror\" \"color Kr\" [{KR} {KR} {KR}]"),
            [
                &format!("-20 -20 {m}"),
                &format!("-20 20 {m}"),
                &format!("20 20 {m}"),
                &format!("20 -20 {m}"),
            ]
        ),
    )
}

pub(super) const LIGHT_Z: f64 = 2.0;
pub(super) const MIRROR_Z: f64 = 3.0;
pub(super) const INTENSITY: f64 = 10.0;
pub(super) const KD: f64 = 0.5;
pub(super) const KR: f64 = 0.8;

/// The floor's radiance under a point light `light_z` above it (Kd / pi I cos / d^2) averaged
/// over the image of a 50-degree camera whose view is `half` wide at the floor, over 8 x 8
/// points of each pixel.
pub(super) fn floor_radiance(half: f64, light_z: f64) -> f64 {
    let n = SIZE as usize * 8;
    let mut sum = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let x = -half + (i as f64 + 0.5) / n as f64 * 2.0 * half;
            let y = -half + (j as f64 + 0.5) / n as f64 * 2.0 * half;
            sum += light_z / libm::pow(x * x + y * y + light_z * light_z, 1.5);
        }
    }
    KD / std::f64::consts::PI * INTENSITY * sum / (n * n) as f64
}

/// A point light between a grey floor and a mirror ceiling: the floor gets the light's
/// irradiance and its image's in the mirror, Kr times that of a light as far above the
/// mirror. The path tracer sees the first alone; bidirectional light tracing carries the
/// second, and the floor's radiance equals Kd / pi times both within 2% (the light tracer's
/// noise at these samples is about 0.6%). One bounce on the camera side and two on the light
/// side: no other light reaches the camera.
#[test]
fn a_point_light_in_a_mirror_lights_the_floor_as_its_image_would() {
    let camera_z = 2.5;
    let text = point_light_under_mirror(
        "\"bidirectional\" \"integer eyedepth\" [1] \"integer lightdepth\" [2]",
        camera_z,
        0.0,
    );
    let half = libm::tan(25.0f64.to_radians()) * camera_z;
    let direct = floor_radiance(half, LIGHT_Z);
    let mirrored = KR * floor_radiance(half, 2.0 * MIRROR_Z - LIGHT_Z);

    let path = f64::from(mean(&render(&text, 16, 1, Transport::Path)).x);
    let bidir = f64::from(mean(&render(&text, 2048, 1, Transport::Bidirectional)).x);
    assert!(
        (path / direct - 1.0).abs() < 0.01,
        "path {path}, direct {direct}"
    );
    let want = direct + mirrored;
    assert!(
        (bidir / want - 1.0).abs() < 0.02,
        "bidirectional {bidir}, expected {want} (direct {direct})"
    );
}

/// The mean image of each of the strategies that make paths of four vertices (two scattering
/// vertices), each alone at full weight, with subpaths of three scattering vertices at most.
fn strategy_means(text: &str, spp: u32) -> Vec<((usize, usize), Vec3)> {
    [(0, 4), (1, 3), (2, 2), (3, 1)]
        .into_iter()
        .map(|(s, t)| {
            let (scene, settings) =
                estimates::build_for(text, &[], SIZE, spp, 1, Transport::Bidirectional);
            let scene = scene.with_only_strategy(s, t);
            ((s, t), mean(&estimates::radiance(&scene, &settings)))
        })
        .collect()
}

/// Each strategy alone (at full weight, no MIS) renders the image of the paths it makes: the
/// room's paths of two bounces (four vertices) come out the same from a camera path that
/// hits the lamp, one that samples it, a camera and a light subpath joined, and light tracing
/// (pbrt-v4's "visualize strategies" idea, as numbers): every mean within 3% of the
/// lowest-noise strategy's (the join's).
#[test]
fn each_strategy_alone_renders_the_same_paths() {
    let text = room("\"bidirectional\" \"integer eyedepth\" [3] \"integer lightdepth\" [3]");
    let means = strategy_means(&text, 512);
    let reference = means[2].1;
    for (strategy, m) in &means {
        for c in 0..3 {
            assert!(
                (m[c] / reference[c] - 1.0).abs() < 0.03,
                "strategy {strategy:?}: {m}, the join's {reference}"
            );
        }
    }
}

/// The room full of fog (scattering 0.6 per unit; the room is 2 across) under a dim sky as
/// well, seen by bidirectional subpaths of 3 scattering vertices each and by a path tracer of
/// depth 6: events in the fog are scattering vertices of either, every strategy joins at
/// them, and the connections carry the fog's transmittance. The fog reaches to infinity, so
/// the sky's light never arrives (a light subpath from it is extinguished before its first
/// surface, as the path tracer's shadow rays toward the sky are). Measured (512 samples a
/// pixel): means 1.0027, 0.9994, 0.9995 of the path tracer's, pixel correlation 0.988. The
/// test fails (measured) with the connections' transmittance dropped (means 2.03 to 2.19
/// times the path tracer's), a cosine at events in the geometry term (0.54) or in the area
/// densities (1.28 to 1.30: the weights no longer sum to one), the sky's light not
/// extinguished from infinity (1.08 to 1.11), or light subpaths leaving the lamp in no volume
/// instead of the fog its shape names (0.93: the ones escaping the room's open side are lost).
#[test]
fn a_room_full_of_fog_renders_as_the_path_tracer_renders_it() {
    let sky = "LightSource \"infinite\" \"color L\" [0.3 0.3 0.3]\nWorldEnd\n";
    let scene = |integrator: &str| in_fog(&room(integrator), 0.6).replacen("WorldEnd\n", sky, 1);
    let (path, bidir) = assert_means_agree(scene, 512, 0.015);
    let correlation = brightness_correlation(&path, &bidir);
    assert!(correlation > 0.98, "correlation {correlation}");
}

/// Each strategy alone renders the paths of two scattering vertices in a room of denser fog
/// (1 per unit; most of those paths have a vertex in the fog) as the path tracer does (its
/// image of depth 2 less its image of depth 1): the camera path hitting the lamp through the
/// fog, sampling it from a surface or an event, joins of every kind, and light tracing from
/// events to the lens. Alone, every strategy but the lamp's hits has fireflies in fog (its
/// connections' 1 / distance^2 is unbounded between events), hence the 5% (measured at
/// seeds 1 and 2, 1024 samples a pixel: within 2.8%). It fails (measured) with the
/// connections' transmittance dropped (the light sample's strategy 2.3 times the path
/// tracer's), a cosine at events in the geometry term (0.63), or light subpaths leaving the
/// lamp in no volume (the join 0.73).
#[test]
fn each_strategy_alone_renders_the_same_paths_in_fog() {
    let sigma_s = 1.0;
    let text = in_fog(
        &room("\"bidirectional\" \"integer eyedepth\" [3] \"integer lightdepth\" [3]"),
        sigma_s,
    );
    let path_of_depth = |depth: u32| {
        let text = in_fog(
            &room(&format!("\"path\" \"integer maxdepth\" [{depth}]")),
            sigma_s,
        );
        mean(&render(&text, 1024, 1, Transport::Path))
    };
    let reference = path_of_depth(2) - path_of_depth(1);
    for (strategy, m) in strategy_means(&text, 1024) {
        let ratio = m / reference;
        for c in 0..3 {
            assert!(
                (ratio[c] - 1.0).abs() < 0.05,
                "strategy {strategy:?}: {m}, the path tracer's {reference}"
            );
        }
    }
}

/// A point light in the fog-filled room, inside a bubble of clear air (a null sphere of radius
/// 0.25 whose inside is a clear volume, the light's `LightSource` in its Exterior): light
/// subpaths leave the light in the bubble and cross into the fog at its surface, and the
/// image is the path tracer's (no caustic paths: both find every light path). The bubble
/// keeps scattering events away from the light, where the 1 / distance^2 of a light sample
/// from an event is unbounded: in open fog the path tracer's mean, short of its rare
/// fireflies, is 2% under bidirectional's at 512 samples a pixel. Measured: means 1.0020,
/// 1.0018, 1.0015 of the path tracer's (seed 2: 0.995), pixel correlation 0.992. It fails
/// (measured) with the connections' transmittance dropped (2.06 to 2.16), a cosine at events
/// in the geometry term (0.61) or in the densities (1.24), or light subpaths leaving the light
/// in the camera's volume (the fog) instead of its Exterior (1.18 to 1.20).
#[test]
fn a_point_light_in_fog_lights_the_room_as_the_path_tracer_sees_it() {
    let at = "0.3 0.2 1.5";
    let scene = |integrator: &str| {
        let text = in_fog(&point_lit_room(integrator, at), 0.8).replacen(
            "WorldBegin\n",
            "WorldBegin\nMakeNamedVolume \"bubble\" \"clear\" \"float fresnel\" [1]\n",
            1,
        );
        let light = text.find("LightSource \"point\"").expect("the point light");
        let end = light + text[light..].find('\n').expect("its line ends") + 1;
        format!(
            "{}AttributeBegin\nInterior \"bubble\"\nMaterial \"null\"\nTranslate {at}\n\
             Shape \"sphere\" \"float radius\" [0.25]\nAttributeEnd\n\
             AttributeBegin\nExterior \"bubble\"\n{}AttributeEnd\n{}",
            &text[..light],
            &text[light..end],
            &text[end..]
        )
    };
    let (path, bidir) = assert_means_agree(scene, 512, 0.015);
    let correlation = brightness_correlation(&path, &bidir);
    assert!(correlation > 0.98, "correlation {correlation}");
}
