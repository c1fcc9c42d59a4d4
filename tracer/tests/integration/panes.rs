//! Panes of architectural glass (`glass` with `"bool architectural" ["true"]`): shadow rays
//! cross them with their transmittance, as LuxRender's do, so the sun through a window is
//! light-sampled, and a path that goes straight through one is weighed against the light sample
//! of the vertex before it. Checked against the pane's transmittance computed here from the
//! Fresnel equations: a thin pane of index n seen at angle theta reflects
//! R' = R + (1 - R)^2 R / (1 - R^2) = 2R / (1 + R) of the light (its two faces' reflections
//! summed), with R the unpolarised Fresnel reflectance, and lets the rest through.

use glam::Vec3;

use super::estimates;

const SIZE: u32 = 24;
const INDEX: f64 = 1.5;

/// What a pane of index [`INDEX`] lets through at incidence cosine `cos_i`.
fn pane_transmittance(cos_i: f64) -> f64 {
    let sin2_t = (1.0 - cos_i * cos_i) / (INDEX * INDEX);
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parallel = (INDEX * cos_i - cos_t) / (INDEX * cos_i + cos_t);
    let r_perpendicular = (cos_i - INDEX * cos_t) / (cos_i + INDEX * cos_t);
    let r = 0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
    1.0 - 2.0 * r / (1.0 + r)
}

/// A camera 1.5 above a grey floor looking down, direct light only (depth 1), `light`, and,
/// when `pane` holds a Kt, an infinite pane of architectural glass at height 2 between the
/// floor and the light (the camera sees the floor without crossing it).
fn scene(light: &str, pane: Option<&str>) -> String {
    let pane = pane.map_or(String::new(), |kt| {
        format!(
            "AttributeBegin\n\
             Material \"glass\" \"bool architectural\" [\"true\"] \"float index\" [{INDEX}] \
             \"color Kt\" [{kt}]\n\
             Translate 0 0 2\n\
             Shape \"plane\" \"normal n\" [0 0 1]\n\
             AttributeEnd\n"
        )
    });
    format!(
        "LookAt 0 0 1.5  0 0 0  0 1 0\n\
         Camera \"perspective\" \"float fov\" [50]\n\
         Film \"fleximage\" \"integer xresolution\" [{SIZE}] \"integer yresolution\" [{SIZE}]\n\
         PixelFilter \"box\"\n\
         SurfaceIntegrator \"path\" \"integer maxdepth\" [1]\n\
         WorldBegin\n\
         {light}\n\
         {pane}\
         {}\
         WorldEnd\n",
        estimates::quad(estimates::MATTE_FLOOR, estimates::FLOOR)
    )
}

fn mean(text: &str, spp: u32, seed: u64) -> Vec3 {
    let (scene, settings) = estimates::build(text, SIZE, spp, seed);
    let image = estimates::radiance(&scene, &settings);
    image.iter().copied().sum::<Vec3>() / image.len() as f32
}

/// The sun (a distant light: a delta, which no BSDF sample finds) reaches the floor through the
/// pane dimmed by the pane's transmittance at its angle, times Kt per channel; without shadow
/// rays through panes the floor is black.
#[test]
fn the_sun_through_a_pane_is_light_sampled_with_its_transmittance() {
    let kt = [1.0, 0.5, 0.25];
    for degrees in [0.0f64, 60.0] {
        let (sin, cos) = libm::sincos(degrees.to_radians());
        let sun = format!(
            "LightSource \"distant\" \"point from\" [{sin} 0 {cos}] \"point to\" [0 0 0] \
             \"color L\" [2 2 2]"
        );
        let open = mean(&scene(&sun, None), 4, 1);
        let behind = mean(&scene(&sun, Some("1 0.5 0.25")), 4, 1);
        assert!(open.x > 0.05, "the floor is lit: {open}");
        let expected = pane_transmittance(cos);
        for c in 0..3 {
            let ratio = f64::from(behind[c] / open[c]);
            assert!(
                (ratio - kt[c] * expected).abs() < 1e-4,
                "{degrees} degrees, channel {c}: ratio {ratio}, expected {}",
                kt[c] * expected
            );
        }
    }
}

/// Under a uniform sky seen through the pane, the floor's irradiance is the sky's times the
/// cosine-weighted mean transmittance over the hemisphere, 2 * integral of T(theta) cos sin
/// over theta. Light samples (through the pane, dimmed) and BSDF samples (going straight on at
/// the pane when its lobe choice transmits) are both weighed by MIS: a BSDF sample weighed as
/// if the light sample could not reach the sky, or a light sample stopped at the pane, moves
/// the mean far beyond the tolerance.
#[test]
fn a_sky_through_a_pane_keeps_the_mean_of_its_two_strategies() {
    let sky = "LightSource \"infinite\" \"color L\" [1 1 1]";
    let steps = 20_000;
    let hemisphere: f64 = (0..steps)
        .map(|i| {
            let theta = (f64::from(i) + 0.5) / f64::from(steps) * std::f64::consts::FRAC_PI_2;
            let (sin, cos) = libm::sincos(theta);
            2.0 * pane_transmittance(cos) * cos * sin * std::f64::consts::FRAC_PI_2
                / f64::from(steps)
        })
        .sum();
    let open = mean(&scene(sky, None), 64, 1);
    let behind =
        (mean(&scene(sky, Some("1 1 1")), 64, 1) + mean(&scene(sky, Some("1 1 1")), 64, 2)) / 2.0;
    let ratio = f64::from(behind.x / open.x);
    assert!(
        (ratio / hemisphere - 1.0).abs() < 0.01,
        "ratio {ratio}, expected {hemisphere}"
    );
}
