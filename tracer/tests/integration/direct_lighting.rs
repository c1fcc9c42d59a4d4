//! LuxRender's direct lighting against what it must equal: the path tracer's first bounce in
//! a room of matte walls, and the analytic light of a floor under a point light seen in a
//! mirror (a specular chain to the first matte vertex, whose direct light alone counts).

use glam::Vec3;
use yat_tracer::integrator::Transport;

use super::bidirectional::{floor_radiance, point_light_under_mirror, room, KR, LIGHT_Z, MIRROR_Z};
use super::estimates;

const SIZE: u32 = 24;

fn render(text: &str, spp: u32, transport: Transport) -> Vec<Vec3> {
    let (scene, settings) = estimates::build_for(text, &[], SIZE, spp, 1, transport);
    estimates::radiance(&scene, &settings)
}

fn mean(image: &[Vec3]) -> Vec3 {
    image.iter().copied().sum::<Vec3>() / image.len() as f32
}

/// Among matte walls, direct lighting is path tracing's first vertex: its light sample and
/// BSDF sample, and nothing after. The same walk draws the same numbers, so the images are the
/// same bits; the full path tracer's is brighter by the walls' interreflections.
#[test]
fn a_matte_room_renders_as_the_path_tracers_first_bounce() {
    let direct = render(
        &room("\"directlighting\" \"integer maxdepth\" [5]"),
        16,
        Transport::DirectLighting,
    );
    let first = render(
        &room("\"path\" \"integer maxdepth\" [1] \"string rrstrategy\" \"none\""),
        16,
        Transport::Path,
    );
    assert_eq!(
        direct, first,
        "direct lighting differs from depth-1 path tracing"
    );
    let full = mean(&render(&room("\"path\""), 16, Transport::Path));
    let direct = mean(&direct);
    assert!(
        direct.x < 0.85 * full.x && direct.x > 0.3 * full.x,
        "direct {direct}, full path tracing {full}"
    );
}

/// A camera under a mirror ceiling looks up at the floor's reflection; a point light hangs
/// between them. Direct lighting follows the mirror to the floor and takes the light's
/// irradiance there: Kr Kd / pi I cos / d^2, within 1%. The floor also sees itself in the
/// mirror (light from floor to mirror to floor), which the path tracer adds and direct
/// lighting leaves out: the path tracer's image is brighter by more than 10%.
#[test]
fn a_mirror_shows_the_floor_lit_by_the_point_light_alone() {
    let camera_z = 1.0;
    let scene = |integrator: &str| point_light_under_mirror(integrator, camera_z, MIRROR_Z);
    // Unfolded at the mirror, the camera looks down at the floor from 2 mirror_z - camera_z.
    let half = libm::tan(25.0f64.to_radians()) * (2.0 * MIRROR_Z - camera_z);
    let want = KR * floor_radiance(half, LIGHT_Z);

    let direct = scene("\"directlighting\"");
    let direct = f64::from(mean(&render(&direct, 64, Transport::DirectLighting)).x);
    assert!(
        (direct / want - 1.0).abs() < 0.01,
        "direct lighting {direct}, expected {want}"
    );
    let path = f64::from(mean(&render(&scene("\"path\""), 64, Transport::Path)).x);
    assert!(path > 1.1 * direct, "path {path}, direct lighting {direct}");
}
