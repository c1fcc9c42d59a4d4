//! Lights (`scene.lights.light<N>`): point, spot, distant and infinite lights as LuxCore's,
//! sun and sky through [`crate::daylight`]; a kind with no LuxCore mapping is left out with a
//! note naming it.

use std::f32::consts::PI;
use std::path::Path;

use glam::Mat4;
use yat_tracer::desc::{LatLongConvention, LightDesc};
use yat_tracer::lights::{DistantLight, InfiniteLight, PointLight, SpotLight};

use crate::options::ExportOptions;
use crate::props::{matrix, quoted, v3, Props};

pub fn write_light(
    p: &mut Props,
    index: usize,
    light: &LightDesc,
    scene_dir: &Path,
    opts: &ExportOptions,
    notes: &mut Vec<String>,
) {
    let prefix = format!("scene.lights.light{index}");
    let mut set = |key: &str, value: String| p.set(format!("{prefix}.{key}"), value);
    match light {
        LightDesc::Point(PointLight {
            position,
            intensity,
        }) => {
            set("type", quoted("point"));
            set("position", v3(*position));
            // LuxCore 2.11's point light sends colour / 4 pi per steradian (measured: a floor
            // under a point light renders 4 pi = 12.57 times darker than YAT's, which gives
            // LuxRender 1.x's intensity, colour x gain).
            set("color", v3(*intensity * (4.0 * std::f32::consts::PI)));
            set("gain", "1 1 1".into());
            set("power", "0".into());
            set("efficency", "0".into());
        }
        LightDesc::Spot(SpotLight {
            position,
            direction,
            intensity,
            cone_angle,
            cone_delta_angle,
        }) => {
            set("type", quoted("spot"));
            set("position", v3(*position));
            set("target", v3(*position + *direction));
            set("color", v3(*intensity));
            set("gain", "1 1 1".into());
            set("power", "0".into());
            set("efficency", "0".into());
            set("coneangle", cone_angle.to_string());
            set("conedeltaangle", cone_delta_angle.to_string());
        }
        // LuxCore's "distant" spreads its colour over a cone (theta, 10 degrees by default),
        // which lit the bump scene at about a tenth of LuxRender's delta light; its
        // "sharpdistant" is the delta light.
        LightDesc::Distant(DistantLight { to_light, radiance }) => {
            set("type", quoted("sharpdistant"));
            set("direction", v3(-*to_light));
            set("color", v3(*radiance));
            set("gain", "1 1 1".into());
        }
        LightDesc::Infinite(InfiniteLight {
            radiance,
            map: None,
            ..
        }) => {
            set("type", quoted("constantinfinite"));
            set("color", v3(*radiance));
            set("gain", "1 1 1".into());
        }
        LightDesc::Infinite(InfiniteLight {
            radiance,
            map: Some(map),
            light_to_world,
        }) => {
            set("type", quoted("infinite"));
            let path = scene_dir.join(&map.filename);
            set("file", quoted(&path.to_string_lossy()));
            set("gamma", map.gamma.to_string());
            set("gain", v3(*radiance));
            // The seed's u = (pi + phi) / 2pi is LuxRender's phi / 2pi half a turn on.
            let turn = match opts.latlong {
                LatLongConvention::LuxRender => Mat4::IDENTITY,
                LatLongConvention::Seed => Mat4::from_rotation_z(PI),
            };
            set("transformation", matrix(&(*light_to_world * turn)));
        }
        LightDesc::Sun(sun) => crate::daylight::write_sun(p, &prefix, sun, notes),
        LightDesc::Sky(sky) => crate::daylight::write_sky(p, &prefix, sky, notes),
        // A kind added later that LuxCore has no mapping for yet.
        #[allow(unreachable_patterns)]
        other => notes.push(format!(
            "light {index} (\"{}\"): not exported",
            other.name()
        )),
    }
}
