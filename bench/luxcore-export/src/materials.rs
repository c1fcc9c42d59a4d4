//! Materials (`scene.materials.<name>`): each YAT material as its LuxCore equivalent, with
//! the emission of an area light when the material is an emitter's.

use glam::Vec3;
use yat_tracer::desc::{AreaLightDesc, ConstOrTexture, Fresnel, MaterialDesc};
use yat_tracer::material::glossy::CoatParams;
use yat_tracer::material::{Glass, Glossy, Matte, MatteTranslucent, Metal, Mirror, Mix};

use crate::materials_extra;
use crate::props::{mat_name, quoted, tex_name, tex_value, v3, Props};

/// Writes material `m` under `name`; `emission` is added for emitting shapes. A null material
/// that emits becomes clear glass (see [`write_null_emitter`]).
pub fn write_material(
    p: &mut Props,
    name: &str,
    m: &MaterialDesc,
    emission: Option<&AreaLightDesc>,
) {
    let prefix = format!("scene.materials.{name}");
    let mut set = |key: &str, value: String| p.set(format!("{prefix}.{key}"), value);
    match m {
        MaterialDesc::Matte(Matte { kd, sigma }) => {
            let rough = *sigma != ConstOrTexture::float(0.0);
            set("type", quoted(if rough { "roughmatte" } else { "matte" }));
            set("kd", tex_value(kd, true));
            if rough {
                set("sigma", tex_value(sigma, false));
            }
        }
        MaterialDesc::Glossy(Glossy {
            kd,
            coat:
                CoatParams {
                    ks,
                    ka,
                    depth,
                    uroughness,
                    vroughness,
                    multibounce,
                },
        }) => {
            set("type", quoted("glossy2"));
            set("kd", tex_value(kd, true));
            set("ks", tex_value(ks, true));
            set("ka", tex_value(ka, true));
            set("d", tex_value(depth, false));
            set("uroughness", tex_value(uroughness, false));
            set("vroughness", tex_value(vroughness, false));
            set("multibounce", u8::from(*multibounce).to_string());
        }
        MaterialDesc::Mirror(Mirror { kr, .. }) => {
            set("type", quoted("mirror"));
            set("kr", tex_value(kr, true));
        }
        MaterialDesc::Glass(Glass {
            kr,
            kt,
            index,
            architectural,
            uroughness,
            vroughness,
            ..
        }) => {
            let rough = *uroughness != ConstOrTexture::float(0.0)
                || *vroughness != ConstOrTexture::float(0.0);
            let kind = match (architectural, rough) {
                (true, _) => "archglass",
                (false, true) => "roughglass",
                (false, false) => "glass",
            };
            set("type", quoted(kind));
            set("kr", tex_value(kr, true));
            set("kt", tex_value(kt, true));
            set("interiorior", tex_value(index, false));
            set("exteriorior", "1".into());
            if rough && !architectural {
                set("uroughness", tex_value(uroughness, false));
                set("vroughness", tex_value(vroughness, false));
            }
        }
        MaterialDesc::Metal(Metal {
            fresnel,
            uroughness,
            vroughness,
        }) => {
            set("type", quoted("metal2"));
            set("fresnel", quoted(&format!("{name}_fresnel")));
            set("uroughness", tex_value(uroughness, false));
            set("vroughness", tex_value(vroughness, false));
            let fprefix = format!("scene.textures.{name}_fresnel");
            match fresnel {
                Fresnel::Reflectance(kr) => {
                    p.set(format!("{fprefix}.type"), quoted("fresnelcolor"));
                    p.set(format!("{fprefix}.kr"), tex_value(kr, true));
                }
                Fresnel::Index(n) => {
                    p.set(format!("{fprefix}.type"), quoted("fresnelconst"));
                    p.set(format!("{fprefix}.n"), tex_value(n, true));
                    p.set(format!("{fprefix}.k"), "0 0 0");
                }
                Fresnel::Conductor { eta, k } => {
                    p.set(format!("{fprefix}.type"), quoted("fresnelconst"));
                    p.set(format!("{fprefix}.n"), v3(*eta));
                    p.set(format!("{fprefix}.k"), v3(*k));
                }
                // As YAT renders metal2 with it: at its mean index.
                Fresnel::Dispersive(curve) => {
                    p.set(format!("{fprefix}.type"), quoted("fresnelconst"));
                    p.set(format!("{fprefix}.n"), v3(Vec3::splat(curve.mean())));
                    p.set(format!("{fprefix}.k"), "0 0 0");
                }
            }
        }
        MaterialDesc::MatteTranslucent(MatteTranslucent { kr, kt, .. }) => {
            // LuxCore always scales kt by 1 - kr (LuxRender 1.x's energyconserving true): a
            // scene without energyconserving transmits less in LuxCore than in YAT.
            set("type", quoted("mattetranslucent"));
            set("kr", tex_value(kr, true));
            set("kt", tex_value(kt, true));
        }
        MaterialDesc::Null(_) if emission.is_some() => write_null_emitter(p, &prefix),
        MaterialDesc::Bumped(material, bump) => {
            write_material(p, name, material, emission);
            // A normalmap texture is exported as LuxCore's normalmap, which bumps through
            // bumptex as well.
            p.set(format!("{prefix}.bumptex"), quoted(&tex_name(bump.map)));
            p.set(
                format!("{prefix}.bumpsamplingdistance"),
                bump.sample_distance,
            );
            return;
        }
        MaterialDesc::Mix(Mix { a, b, amount }) => {
            set("type", quoted("mix"));
            set("material1", quoted(&mat_name(*a)));
            set("material2", quoted(&mat_name(*b)));
            set("amount", tex_value(amount, false));
        }
        // The LuxRender 1.x extras; kinds with no parameters LuxCore needs (null) go by
        // their name.
        other => {
            if !materials_extra::write(p, &prefix, other) {
                p.set(format!("{prefix}.type"), quoted(other.name()));
            }
        }
    }
    if let Some(group) = emission.map(|e| e.group).filter(|&g| g > 0) {
        p.set(format!("{prefix}.emission.id"), group);
    }
    match emission.map(|e| (e, e.radiance())) {
        Some((_, Some(radiance))) => {
            p.set(format!("{prefix}.emission"), v3(radiance));
            p.set(format!("{prefix}.emission.gain"), "1 1 1");
            p.set(format!("{prefix}.emission.power"), 0);
            p.set(format!("{prefix}.emission.efficency"), 0);
        }
        // A texture's mean luminance needs its decoded images, which the export does not
        // read: LuxCore normalises power and efficacy by its own mean of the texture.
        Some((e, None)) => {
            p.set(format!("{prefix}.emission"), tex_value(&e.l, true));
            p.set(format!("{prefix}.emission.gain"), v3(Vec3::splat(e.gain)));
            p.set(format!("{prefix}.emission.power"), e.power);
            p.set(format!("{prefix}.emission.efficency"), e.efficacy);
        }
        None => {}
    }
}

/// A lamp with YAT's `null` material emits and is otherwise invisible: a ray that reaches it
/// collects the emission and goes on through unchanged. LuxCore's own `null` material is no
/// good for that: it is a pass-through surface, skipped inside scene intersection, so rays
/// never stop on it and its emission is only ever seen by light sampling (MIS loses the BSDF
/// half). Black matte (what this export once wrote) stops and absorbs every ray that reaches
/// the lamp, darkening what lies behind it (about 1% in the Cornell box). Clear glass with no
/// reflection and matched indices is a real hit (emission with MIS) whose only event carries
/// the ray straight on with weight 1. What differs: it blocks shadow rays, which YAT's null
/// surfaces let through (the light samples of what lies behind a lamp: 0.1% of Captain
/// Falcon's direct light), and LuxCore counts the crossing as a specular bounce of the path
/// depth, YAT does not.
fn write_null_emitter(p: &mut Props, prefix: &str) {
    p.set(format!("{prefix}.type"), quoted("glass"));
    p.set(format!("{prefix}.kr"), "0 0 0");
    p.set(format!("{prefix}.kt"), "1 1 1");
    p.set(format!("{prefix}.interiorior"), 1);
    p.set(format!("{prefix}.exteriorior"), 1);
}
