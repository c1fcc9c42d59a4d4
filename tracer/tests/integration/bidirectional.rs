//! Bidirectional path tracing against what it must equal: the path tracer's image where both
//! can render the light, and the analytic irradiance of a point light seen in a mirror, which
//! only light tracing carries (a point light reflected by a mirror onto a floor: no camera path
//! finds a point light behind a mirror).

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

/// The room's image is the path tracer's: bidirectional subpaths of 3 scattering vertices
/// each make every path of up to 6, as a path tracer of depth 6 does. The means agree within
/// 1% (measured: 0.1%), and the pixels correlate.
#[test]
fn a_room_renders_as_the_path_tracer_renders_it() {
    let bidir = room("\"bidirectional\" \"integer eyedepth\" [3] \"integer lightdepth\" [3]");
    let path = room("\"path\" \"integer maxdepth\" [6]");
    let path = render(&path, 1024, 1, Transport::Path);
    let bidir = render(&bidir, 1024, 1, Transport::Bidirectional);
    let (p, b) = (mean(&path), mean(&bidir));
    for c in 0..3 {
        assert!(
            (b[c] / p[c] - 1.0).abs() < 0.01,
            "bidirectional {b}, path {p}"
        );
    }
    let lum = |v: &Vec3| f64::from(v.x + v.y + v.z);
    let (mp, mb) = (lum(&p), lum(&b));
    let (mut cov, mut vp, mut vb) = (0.0, 0.0, 0.0);
    for (x, y) in path.iter().zip(&bidir) {
        let (dx, dy) = (lum(x) - mp, lum(y) - mb);
        cov += dx * dy;
        vp += dx * dx;
        vb += dy * dy;
    }
    let correlation = cov / (vp * vb).sqrt();
    assert!(correlation > 0.99, "correlation {correlation}");
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
    let bidir = null_lamp("\"bidirectional\" \"integer eyedepth\" [3] \"integer lightdepth\" [3]");
    let path = null_lamp("\"path\" \"integer maxdepth\" [6]");
    let (path, bidir) = (
        render(&path, 256, 1, Transport::Path),
        render(&bidir, 256, 1, Transport::Bidirectional),
    );
    let brightest = path.iter().map(|v| v.x).fold(0.0, f32::max);
    assert!(brightest > 7.0, "the camera sees the lamp: {brightest}");
    let (p, b) = (mean(&path), mean(&bidir));
    for c in 0..3 {
        assert!(
            (b[c] / p[c] - 1.0).abs() < 0.01,
            "bidirectional {b}, path {p}"
        );
    }
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
    let bidir = scene("\"bidirectional\" \"integer eyedepth\" [3] \"integer lightdepth\" [3]");
    let path = scene("\"path\" \"integer maxdepth\" [6]");
    let (p, b) = (
        mean(&render(&path, 256, 1, Transport::Path)),
        mean(&render(&bidir, 256, 1, Transport::Bidirectional)),
    );
    for c in 0..3 {
        assert!(
            (b[c] / p[c] - 1.0).abs() < 0.01,
            "bidirectional {b}, path {p}"
        );
    }
}

/// A point light between a grey floor and a mirror ceiling: the floor gets the light's
/// irradiance and its image's in the mirror, Kr times that of a light as far above the
/// mirror. The path tracer sees the first alone; bidirectional light tracing carries the
/// second, and the floor's radiance equals Kd / pi times both within 2% (the light tracer's
/// noise at these samples is about 0.6%). One bounce on the camera side and two on the light
/// side: no other light reaches the camera.
#[test]
fn a_point_light_in_a_mirror_lights_the_floor_as_its_image_would() {
    let (light_z, mirror_z, camera_z) = (2.0f64, 3.0f64, 2.5f64);
    let (intensity, kd, kr) = (10.0f64, 0.5f64, 0.8f64);
    let text = format!(
        "LookAt 0 0 {camera_z}  0 0 0  0 1 0\n\
         Camera \"perspective\" \"float fov\" [50]\n\
         Film \"fleximage\" \"integer xresolution\" [{SIZE}] \"integer yresolution\" [{SIZE}]\n\
         PixelFilter \"box\"\n\
         SurfaceIntegrator \"bidirectional\" \"integer eyedepth\" [1] \"integer lightdepth\" [2]\n\
         WorldBegin\n\
         LightSource \"point\" \"point from\" [0 0 {light_z}] \"color L\" [{intensity} {intensity} {intensity}]\n\
         {}{}WorldEnd\n",
        estimates::quad(
            &format!("Material \"matte\" \"color Kd\" [{kd} {kd} {kd}]"),
            ["-20 -20 0", "20 -20 0", "20 20 0", "-20 20 0"]
        ),
        estimates::quad(
            &format!("Material \"mirror\" \"color Kr\" [{kr} {kr} {kr}]"),
            [
                &format!("-20 -20 {mirror_z}"),
                &format!("-20 20 {mirror_z}"),
                &format!("20 20 {mirror_z}"),
                &format!("20 -20 {mirror_z}"),
            ]
        ),
    );
    // The floor seen through each pixel, averaged over 8 x 8 points of the pixel.
    let half = libm::tan(25.0f64.to_radians()) * camera_z;
    let image_z = 2.0 * mirror_z - light_z;
    let (mut direct, mut mirrored) = (0.0f64, 0.0f64);
    let n = SIZE as usize * 8;
    for i in 0..n {
        for j in 0..n {
            let x = -half + (i as f64 + 0.5) / n as f64 * 2.0 * half;
            let y = -half + (j as f64 + 0.5) / n as f64 * 2.0 * half;
            let r2 = x * x + y * y;
            direct += light_z / libm::pow(r2 + light_z * light_z, 1.5);
            mirrored += image_z / libm::pow(r2 + image_z * image_z, 1.5);
        }
    }
    let scale = kd / std::f64::consts::PI * intensity / (n * n) as f64;
    let (direct, mirrored) = (direct * scale, kr * mirrored * scale);

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

/// Each strategy alone (at full weight, no MIS) renders the image of the paths it makes: the
/// room's paths of two bounces (four vertices) come out the same from a camera path that
/// hits the lamp, one that samples it, a camera and a light subpath joined, and light tracing
/// (pbrt-v4's "visualize strategies" idea, as numbers): every mean within 3% of the
/// lowest-noise strategy's (the join's).
#[test]
fn each_strategy_alone_renders_the_same_paths() {
    let text = room("\"bidirectional\" \"integer eyedepth\" [3] \"integer lightdepth\" [3]");
    let strategies = [(0, 4), (1, 3), (2, 2), (3, 1)];
    let means: Vec<Vec3> = strategies
        .iter()
        .map(|&(s, t)| {
            let (scene, settings) =
                estimates::build_for(&text, &[], SIZE, 512, 1, Transport::Bidirectional);
            let scene = scene.with_only_strategy(s, t);
            mean(&estimates::radiance(&scene, &settings))
        })
        .collect();
    let reference = means[2];
    for (strategy, m) in strategies.iter().zip(&means) {
        for c in 0..3 {
            assert!(
                (m[c] / reference[c] - 1.0).abs() < 0.03,
                "strategy {strategy:?}: {m}, the join's {reference}"
            );
        }
    }
}
