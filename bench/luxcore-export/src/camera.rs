//! The camera (`scene.camera.*` in `scene.scn`) and the render configuration (`render.cfg`:
//! film size and pixel filter).

use glam::Vec3;
use yat_tracer::camera::aperture::LensDistribution;
use yat_tracer::desc::{CameraKind, FilterKind, SceneDesc};

use crate::error::ExportError;
use crate::props::{quoted, v3, Props};

pub fn write_camera(desc: &SceneDesc, p: &mut Props) -> Result<(), ExportError> {
    let c = &desc.camera;
    let kind = match c.kind {
        CameraKind::Perspective { fov } => {
            p.set("scene.camera.fieldofview", fov);
            "perspective"
        }
        CameraKind::Orthographic => "orthographic",
        CameraKind::Fisheye { .. } => {
            return Err(ExportError::Unsupported(
                "LuxCore has no fisheye camera".into(),
            ))
        }
    };
    let m = c.camera_to_world;
    let orig = m.transform_point3(Vec3::ZERO);
    let dir = m.transform_vector3(Vec3::Z).normalize();
    let up = m.transform_vector3(Vec3::Y).normalize();
    // LuxRender's LookAt puts image right along dir x up; a camera transform that mirrors
    // this would render mirrored in LuxCore, which builds its camera from orig, target, up.
    let right = m.transform_vector3(Vec3::X);
    if right.dot(dir.cross(up)) <= 0.0 {
        return Err(ExportError::Unsupported(
            "the camera transform mirrors the image".into(),
        ));
    }
    p.set("scene.camera.type", quoted(kind));
    p.set("scene.camera.lookat.orig", v3(orig));
    p.set("scene.camera.lookat.target", v3(orig + dir));
    p.set("scene.camera.up", v3(up));
    let [x0, x1, y0, y1] = c.screen_window;
    p.set("scene.camera.screenwindow", format!("{x0} {x1} {y0} {y1}"));
    p.set("scene.camera.lensradius", c.lens_radius);
    p.set("scene.camera.focaldistance", c.focal_distance);
    p.set("scene.camera.autofocus.enable", u8::from(c.autofocus));
    if !c.aperture.is_round() {
        let (kind, power) = match c.aperture.distribution {
            LensDistribution::Uniform => ("UNIFORM", None),
            LensDistribution::Exponential { power } => ("EXPONENTIAL", Some(power)),
            LensDistribution::InverseExponential { power } => ("INVERSEEXPONENTIAL", Some(power)),
            LensDistribution::Gaussian => ("GAUSSIAN", None),
            LensDistribution::InverseGaussian => ("INVERSEGAUSSIAN", None),
        };
        p.set("scene.camera.bokeh.blades", c.aperture.blades);
        p.set("scene.camera.bokeh.distribution.type", quoted(kind));
        if let Some(power) = power {
            p.set("scene.camera.bokeh.power", power);
        }
    }
    p.set("scene.camera.cliphither", c.hither);
    p.set("scene.camera.clipyon", c.yon);
    Ok(())
}

/// `render.cfg` without the engine, sampler, depth and halt conditions (the caller's).
pub fn write_config(desc: &SceneDesc) -> String {
    let mut c = Props::default();
    c.set("scene.file", quoted("scene.scn"));
    c.set("film.width", desc.film.xresolution);
    c.set("film.height", desc.film.yresolution);
    let f = &desc.filter;
    let kind = match f.kind {
        FilterKind::Box => "BOX",
        FilterKind::Triangle | FilterKind::Sinc { .. } => "BLACKMANHARRIS",
        FilterKind::Gaussian { alpha } => {
            c.set("film.filter.gaussian.alpha", alpha);
            "GAUSSIAN"
        }
        // LuxCore's mitchell is separable, LuxRender's (and YAT's) radial: the nearest it
        // has, at the width rendered (a supersampled one's 5/3 of the file's).
        FilterKind::Mitchell { b, c: cc, .. } => {
            c.set("film.filter.mitchell.b", b);
            c.set("film.filter.mitchell.c", cc);
            "MITCHELL"
        }
        FilterKind::CatmullRom => {
            c.set("film.filter.mitchell.b", 0.0);
            c.set("film.filter.mitchell.c", 0.5);
            "MITCHELL"
        }
        FilterKind::BlackmanHarris => "BLACKMANHARRIS",
    };
    c.set("film.filter.type", quoted(kind));
    let [xwidth, ywidth] = f.half_widths();
    c.set("film.filter.xwidth", xwidth);
    c.set("film.filter.ywidth", ywidth);
    c.into_text()
}
