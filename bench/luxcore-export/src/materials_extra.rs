//! The LuxRender 1.x materials beyond the course's set, as LuxCore's equivalents: carpaint,
//! velvet, cloth, glossycoating and glossytranslucent have LuxCore materials of the same name
//! and parameters (cloth's `presetname` is LuxCore's `preset`). Shinymetal, layered and scatter
//! have none (LuxCore refuses a scene naming them) and go out as the nearest it has, which
//! bench/RESULTS.md measures: shinymetal as metal2 with Ks as its Fresnel colour (its glossy
//! lobe; the mirror lobe of Kr is left out), layered as a mix of its top layer over the next by
//! the top's opacity, scatter as matte of its Kd.

use yat_tracer::desc::MaterialDesc;
use yat_tracer::material::glossy::CoatParams;
use yat_tracer::material::{
    CarPaint, Cloth, GlossyCoating, GlossyTranslucent, Layered, Scatter, ShinyMetal, Velvet,
};

use crate::props::{mat_name, quoted, tex_value, Props};

/// The coat's parameters under `{prefix}.<key>{suffix}` (glossytranslucent's back face has
/// the suffix `_bf`). Ks already has the index folded in, so the index is not written.
fn write_coat(p: &mut Props, prefix: &str, suffix: &str, c: &CoatParams) {
    p.set(format!("{prefix}.ks{suffix}"), tex_value(&c.ks, true));
    p.set(format!("{prefix}.ka{suffix}"), tex_value(&c.ka, true));
    p.set(format!("{prefix}.d{suffix}"), tex_value(&c.depth, false));
    p.set(
        format!("{prefix}.uroughness{suffix}"),
        tex_value(&c.uroughness, false),
    );
    p.set(
        format!("{prefix}.vroughness{suffix}"),
        tex_value(&c.vroughness, false),
    );
    p.set(
        format!("{prefix}.multibounce{suffix}"),
        u8::from(c.multibounce),
    );
}

/// Writes `m` under `prefix` when it is one of these materials; false otherwise.
pub fn write(p: &mut Props, prefix: &str, m: &MaterialDesc) -> bool {
    let mut set = |key: &str, value: String| p.set(format!("{prefix}.{key}"), value);
    match m {
        MaterialDesc::CarPaint(CarPaint {
            kd,
            ks,
            r,
            m,
            ka,
            depth,
        }) => {
            set("type", quoted("carpaint"));
            set("kd", tex_value(kd, true));
            for i in 0..3 {
                set(&format!("ks{}", i + 1), tex_value(&ks[i], true));
                set(&format!("r{}", i + 1), tex_value(&r[i], false));
                set(&format!("m{}", i + 1), tex_value(&m[i], false));
            }
            set("ka", tex_value(ka, true));
            set("d", tex_value(depth, false));
        }
        MaterialDesc::Velvet(Velvet {
            kd,
            p: coeffs,
            thickness,
        }) => {
            set("type", quoted("velvet"));
            set("kd", tex_value(kd, true));
            for (i, c) in coeffs.iter().enumerate() {
                set(&format!("p{}", i + 1), tex_value(c, false));
            }
            set("thickness", tex_value(thickness, false));
        }
        MaterialDesc::Cloth(Cloth {
            preset,
            warp,
            weft,
            repeat,
        }) => {
            set("type", quoted("cloth"));
            set("preset", quoted(preset.name));
            set("warp_kd", tex_value(&warp[0], true));
            set("warp_ks", tex_value(&warp[1], true));
            set("weft_kd", tex_value(&weft[0], true));
            set("weft_ks", tex_value(&weft[1], true));
            set("repeat_u", repeat.x.to_string());
            set("repeat_v", repeat.y.to_string());
        }
        MaterialDesc::GlossyCoating(GlossyCoating { base, coat }) => {
            set("type", quoted("glossycoating"));
            set("base", quoted(&mat_name(*base)));
            write_coat(p, prefix, "", coat);
        }
        MaterialDesc::GlossyTranslucent(GlossyTranslucent {
            kd,
            kt,
            front,
            back,
        }) => {
            set("type", quoted("glossytranslucent"));
            set("kd", tex_value(kd, true));
            set("kt", tex_value(kt, true));
            write_coat(p, prefix, "", front);
            write_coat(p, prefix, "_bf", back.as_ref().unwrap_or(front));
        }
        MaterialDesc::ShinyMetal(ShinyMetal {
            ks,
            uroughness,
            vroughness,
            ..
        }) => {
            let fresnel = format!("{}_fresnel", prefix.replace('.', "_"));
            set("type", quoted("metal2"));
            set("fresnel", quoted(&fresnel));
            set("uroughness", tex_value(uroughness, false));
            set("vroughness", tex_value(vroughness, false));
            p.set(
                format!("scene.textures.{fresnel}.type"),
                quoted("fresnelcolor"),
            );
            p.set(format!("scene.textures.{fresnel}.kr"), tex_value(ks, true));
        }
        // The top layer over the next by its opacity (LuxCore's mix: amount 1 is material2).
        MaterialDesc::Layered(Layered { layers }) => match &layers[..] {
            [] => set("type", quoted("null")),
            [(top, opacity), rest @ ..] => {
                let below = rest.first().map_or(*top, |(m, _)| *m);
                set("type", quoted("mix"));
                set("material1", quoted(&mat_name(below)));
                set("material2", quoted(&mat_name(*top)));
                set("amount", tex_value(opacity, false));
            }
        },
        MaterialDesc::Scatter(Scatter { kd, .. }) => {
            set("type", quoted("matte"));
            set("kd", tex_value(kd, true));
        }
        _ => return false,
    }
    true
}
