//! Volumes (`scene.volumes.vol<N>`): LuxRender's clear and homogeneous named volumes as
//! LuxCore's `clear` and `homogeneous` (with multiple scattering on, as YAT's path tracer
//! scatters as often as the path lasts); the camera's volume; a shape's Interior and Exterior
//! as its material's `volume.interior` and `volume.exterior` (LuxCore keeps volumes on
//! materials, so a shape with volumes gets its own copy of its material).

use yat_tracer::desc::{MediumDesc, MediumId, SceneDesc, ShapeMedia};

use crate::props::{quoted, v3, Props};

pub fn vol_name(id: MediumId) -> String {
    format!("vol{}", id.0)
}

/// Writes every volume and the camera's.
pub fn write_volumes(desc: &SceneDesc, p: &mut Props) {
    for (i, medium) in desc.volumes.media.iter().enumerate() {
        let prefix = format!("scene.volumes.{}", vol_name(MediumId(i as u32)));
        let mut set = |key: &str, value: String| p.set(format!("{prefix}.{key}"), value);
        set("type", quoted(medium.name()));
        set("ior", medium.index().to_string());
        match medium {
            MediumDesc::Clear(c) => set("absorption", v3(c.absorption)),
            MediumDesc::Homogeneous(h) => {
                set("absorption", v3(h.sigma_a));
                set("scattering", v3(h.sigma_s));
                set("asymmetry", v3(h.g));
                set("multiscattering", "1".into());
            }
        }
    }
    if let Some(camera) = desc.volumes.camera {
        p.set("scene.camera.volume", quoted(&vol_name(camera)));
    }
}

/// Sets the volumes of material `name` (written for one shape only).
pub fn set_material_volumes(p: &mut Props, name: &str, media: ShapeMedia) {
    if let Some(v) = media.interior {
        p.set(
            format!("scene.materials.{name}.volume.interior"),
            quoted(&vol_name(v)),
        );
    }
    if let Some(v) = media.exterior {
        p.set(
            format!("scene.materials.{name}.volume.exterior"),
            quoted(&vol_name(v)),
        );
    }
}
