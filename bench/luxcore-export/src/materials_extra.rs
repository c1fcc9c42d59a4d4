//! The LuxRender 1.x materials beyond the course's set, as LuxCore's equivalents: carpaint,
//! velvet, cloth, glossycoating and glossytranslucent have LuxCore materials of the same name
//! and parameters (cloth's `presetname` is LuxCore's `preset`); shinymetal, layered and scatter have none and go out by their name (LuxCore
//! then shows its default), which bench/RESULTS.md explains.

use yat_tracer::desc::MaterialDesc;
use yat_tracer::material::glossy::CoatParams;
use yat_tracer::material::{CarPaint, Cloth, GlossyCoating, GlossyTranslucent, Velvet};

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
        _ => return false,
    }
    true
}
