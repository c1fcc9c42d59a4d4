//! Sun and sky lights (`scene.lights.light<N>`) as LuxCore's `sun` and `sky2`. Both renderers
//! use the same units (683 lm/W x the spectral model), so the gains carry over unchanged.
//! LuxCore has no Preetham sky: a `sky` is written as `sky2` (Hosek-Wilkie) with its
//! turbidity and a note, so a comparison shows the difference between the two models.

use yat_tracer::lights::{SkyLight, SkyModel, SunLight};

use crate::props::{matrix, quoted, v3, Props};

/// LuxCore's `sun` clamps `relsize` to at least this.
const LUXCORE_MIN_RELSIZE: f32 = 1.0;

pub fn write_sun(p: &mut Props, prefix: &str, sun: &SunLight, notes: &mut Vec<String>) {
    let mut set = |key: &str, value: String| p.set(format!("{prefix}.{key}"), value);
    set("type", quoted("sun"));
    // Already in world space.
    set("dir", v3(sun.to_sun));
    set("turbidity", sun.turbidity.to_string());
    set("relsize", sun.relsize.to_string());
    set("gain", v3(glam::Vec3::splat(sun.gain)));
    if sun.relsize < LUXCORE_MIN_RELSIZE {
        notes.push(format!(
            "{prefix}: sun relsize {} is read by LuxCore as {LUXCORE_MIN_RELSIZE} (a larger, dimmer disc of the same power)",
            sun.relsize
        ));
    }
}

pub fn write_sky(p: &mut Props, prefix: &str, sky: &SkyLight, notes: &mut Vec<String>) {
    let mut set = |key: &str, value: String| p.set(format!("{prefix}.{key}"), value);
    set("type", quoted("sky2"));
    // In light space, mapped by the transformation like YAT's.
    set("dir", v3(sky.sundir));
    set("turbidity", sky.turbidity.to_string());
    set("gain", v3(glam::Vec3::splat(sky.gain)));
    set("groundalbedo", "0 0 0".into());
    set("transformation", matrix(&sky.light_to_world));
    if let SkyModel::Preetham { .. } = sky.model {
        notes.push(format!(
            "{prefix}: LuxCore has no Preetham \"sky\"; written as the Hosek-Wilkie \"sky2\""
        ));
    }
}
