//! Fresnel textures: not evaluated per hit, but a [`Fresnel`] term bound to the texture's name
//! that metal2 (`"texture fresnel" "name"`) folds into its description, and a volume's
//! `fresnel` reads as its index (what glass2 refracts with).
//!
//! ```text
//! Texture "name" "fresnel" "fresnelcolor" "color Kr" [0.9 0.6 0.2]
//! Texture "name" "fresnel" "fresnelname" "string name" "copper"
//! Texture "name" "fresnel" "constant" "float value" 1.5
//! Texture "name" "fresnel" "cauchy" "float cauchya" [1.5] "float cauchyb" [0.0042]
//! Texture "name" "fresnel" "abbe" "float n" [1.5168] "float V" [64.17]
//! Texture "name" "fresnel" "sellmeier" "float A" [1] "float B" [1.04 0.23 1.01]
//!     "float C" [0.006 0.02 103.6]
//! Texture "name" "fresnel" "sopra" "string filename" "bk7.nk"
//! ```
//!
//! | type                   | parameter                    | default   | gives |
//! |------------------------|------------------------------|-----------|-------|
//! | `fresnelcolor`         | `Kr` (texture or colour)     | 0.5       | a normal-incidence reflectance |
//! | `fresnelname`, `preset`| `string filename` or `string name` | aluminium | a built-in metal's complex index (an unknown name or an .nk file warns and gives aluminium) |
//! | `constant`             | `float value`                | 1.5       | a real index of refraction |
//! | `cauchy`               | `cauchyb` (um^2), `cauchya`, `index` | 0; `index - cauchyb / (0.38 x 0.72 um^2)` given `index`, else 1.5; none | the index `cauchya + cauchyb / lambda^2` ([`IndexCurve::Cauchy`]); `index` is its mean over LuxRender's 380-720 nm |
//! | `abbe`                 | `n`, `V`, `type` (`d`, `D`, `e`, `custom`: `lambda_D`, `lambda_F`, `lambda_C` in nm) | 1.5168, 64.17 (BK7), `d` (587.5618, 486.13, 656.28 nm) | the Cauchy index of refractive index n at lambda_D and Abbe number V over lambda_F and lambda_C |
//! | `sellmeier`            | `A`, `B`, `C` (as many Bs as Cs; C in um^2) | 1, none, none | the index `sqrt(A + sum of B lambda^2 / (lambda^2 - C))` ([`IndexCurve::Sellmeier`]) |
//! | `sopra`, `luxpop`      | `string filename`            | none      | the real index n of a refractive-index data file (the formats of [`crate::material::nk`]), interpolated between its samples ([`IndexCurve::Table`]) |
//!
//! The last four are LuxRender's dielectric fresnel textures, whose index varies with the
//! wavelength ([`Fresnel::Dispersive`]): a volume's index where glass2 with `dispersion` makes
//! a path take one wavelength. LuxRender also accepts the `fresnelcolor`, `fresnelname` and
//! `preset` types declared "color" (or "float"); any other type declared "fresnel" warns and
//! leaves the name undefined, as does a `sellmeier` whose B and C differ in count or a data
//! file that cannot be read.

use glam::Vec3;

use crate::assets::AssetKind;
use crate::diag::SourcePos;
use crate::material::nk;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::{ConstOrTexture, Fresnel};
use crate::wavelength::{IndexCurve, CAUCHY_B_PER_UM2, LUX_SPECTRUM_NM};

pub const DEFAULT_KR: f32 = 0.5;
pub const DEFAULT_METAL: &str = "aluminium";
pub const DEFAULT_INDEX: f32 = 1.5;
/// `cauchy`'s `cauchyb` (um^2) and its `cauchya` when no `index` is given.
pub const DEFAULT_CAUCHY_B: f32 = 0.0;
pub const DEFAULT_CAUCHY_A: f32 = 1.5;
/// `abbe`'s refractive index and Abbe number: BK7's.
pub const DEFAULT_ABBE_N: f32 = 1.5168;
pub const DEFAULT_ABBE_V: f32 = 64.17;
/// `abbe`'s Fraunhofer lines (nm) by `type`: the d, F and C lines; D's sodium line for
/// lambda_D; e, F' and C' for `e`.
pub const ABBE_D_LINES: [f32; 3] = [587.5618, 486.13, 656.28];
pub const ABBE_SODIUM_D_NM: f32 = 589.29;
pub const ABBE_E_LINES: [f32; 3] = [546.07, 479.99, 643.85];
/// `sellmeier`'s A.
pub const DEFAULT_SELLMEIER_A: f32 = 1.0;

/// The fresnel texture types LuxRender accepts under any declared kind.
pub fn is_fresnel_type(class: &str) -> bool {
    matches!(class, "fresnelcolor" | "fresnelname" | "preset")
}

/// The Fresnel term of a fresnel texture of type `class`; `None` (with a warning) for a type
/// this renderer does not know.
pub fn read(
    class: &str,
    params: &ParamList,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<Option<Fresnel>, ParseError> {
    Ok(Some(match class {
        "fresnelcolor" => {
            let kr = params.tex_color("Kr", Vec3::splat(DEFAULT_KR))?;
            Fresnel::Reflectance(ctx.tex(kr, true, Vec3::splat(DEFAULT_KR)))
        }
        "fresnelname" | "preset" => {
            let name = match params.string("filename")? {
                Some(f) => f,
                None => params.string_or("name", DEFAULT_METAL)?,
            };
            let (eta, k) = ctx.metal_by_name(&name, pos);
            Fresnel::Conductor { eta, k }
        }
        "constant" => Fresnel::Index(ConstOrTexture::float(params.float("value", DEFAULT_INDEX)?)),
        "cauchy" => Fresnel::Dispersive(cauchy(params)?),
        "abbe" => Fresnel::Dispersive(abbe(params)?),
        "sellmeier" => {
            match sellmeier(params)? {
                Ok(curve) => Fresnel::Dispersive(curve),
                Err(message) => {
                    ctx.warn(pos, format!("fresnel texture \"sellmeier\": {message}; the texture is left undefined"));
                    return Ok(None);
                }
            }
        }
        "sopra" | "luxpop" => match tabulated(class, params, pos, ctx)? {
            Some(curve) => Fresnel::Dispersive(curve),
            None => return Ok(None),
        },
        other => {
            params.ignore_all();
            ctx.warn(pos, format!("fresnel texture type \"{other}\" is not supported; the texture is left undefined"));
            return Ok(None);
        }
    }))
}

/// `cauchy`: LuxRender's `cauchya` defaults so that `index` is the mean index over its
/// spectrum (the mean of 1 / lambda^2 over 380-720 nm is 1 / (380 x 720 nm^2)).
fn cauchy(params: &ParamList) -> Result<IndexCurve, ParseError> {
    let b = params.float("cauchyb", DEFAULT_CAUCHY_B)? * CAUCHY_B_PER_UM2;
    let index = params.float("index", -1.0)?;
    let default_a = if index > 0.0 {
        index - b / (LUX_SPECTRUM_NM.0 * LUX_SPECTRUM_NM.1)
    } else {
        DEFAULT_CAUCHY_A
    };
    let a = params.float("cauchya", default_a)?;
    Ok(IndexCurve::Cauchy { a, b })
}

/// `abbe`: the Cauchy curve through index `n` at lambda_D whose Abbe number
/// `(n - 1) / (n(lambda_F) - n(lambda_C))` is `V`.
fn abbe(params: &ParamList) -> Result<IndexCurve, ParseError> {
    let [mut d, mut f, mut c] = ABBE_D_LINES;
    match params.string_or("type", "d")?.as_str() {
        "D" => d = ABBE_SODIUM_D_NM,
        "e" => [d, f, c] = ABBE_E_LINES,
        "custom" => {
            d = params.float("lambda_D", d)?;
            f = params.float("lambda_F", f)?;
            c = params.float("lambda_C", c)?;
        }
        _ => {}
    }
    let v = params.float("V", DEFAULT_ABBE_V)?;
    let n = params.float("n", DEFAULT_ABBE_N)?;
    // LuxRender's arithmetic: the lines in um, squared; B in um^2.
    let [d2, f2, c2] = [d, f, c].map(|nm| (nm * 1e-3) * (nm * 1e-3));
    let b = (n - 1.0) * (c2 * f2) / (v * (c2 - f2));
    Ok(IndexCurve::Cauchy {
        a: n - b / d2,
        b: b * CAUCHY_B_PER_UM2,
    })
}

/// `sellmeier`'s curve, or what is wrong with its parameters.
fn sellmeier(params: &ParamList) -> Result<Result<IndexCurve, String>, ParseError> {
    let a = params.float("A", DEFAULT_SELLMEIER_A)?;
    let b = params.floats("B")?.map(|(v, _)| v).unwrap_or_default();
    let c = params.floats("C")?.map(|(v, _)| v).unwrap_or_default();
    if b.len() != c.len() {
        return Ok(Err(format!(
            "{} B and {} C coefficients (they go in pairs)",
            b.len(),
            c.len()
        )));
    }
    // C in um^2 to nm^2.
    let terms = b.into_iter().zip(c.into_iter().map(|c| c * 1e6)).collect();
    Ok(Ok(IndexCurve::Sellmeier { a, terms }))
}

/// `sopra` or `luxpop`: the file's real index by wavelength; None (with a warning or a note)
/// when it cannot be read or holds no sample. A malformed file is an error naming its line.
fn tabulated(
    class: &str,
    params: &ParamList,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<Option<IndexCurve>, ParseError> {
    let Some(name) = params.string("filename")? else {
        ctx.warn(
            pos,
            format!(
                "fresnel texture \"{class}\" names no \"filename\"; the texture is left undefined"
            ),
        );
        return Ok(None);
    };
    let bytes = match ctx.read_asset(&name, AssetKind::Nk, pos) {
        Ok(bytes) => bytes,
        Err(ParseError::Asset { error, .. }) => {
            ctx.warn(
                pos,
                format!("fresnel texture \"{class}\": \"{name}\" cannot be read ({error}); the texture is left undefined"),
            );
            return Ok(None);
        }
        Err(e) => return Err(e),
    };
    let samples = nk::read_index(&bytes).map_err(|e| ParseError::Invalid {
        pos: pos.clone(),
        message: match e.line {
            0 => format!("index data file \"{name}\": {}", e.message),
            line => format!("index data file \"{name}\" line {line}: {}", e.message),
        },
    })?;
    Ok(Some(IndexCurve::Table(samples)))
}
