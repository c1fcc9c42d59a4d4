//! The colour of a named lamp: LuxRender's measured lamp spectra, as RGB hues.
//!
//! ```text
//! Texture "name" "color" "lampspectrum" "string name" ["HPS"]
//! ```
//!
//! | parameter     | default       | notes |
//! |---------------|---------------|-------|
//! | `string name` | Incandescent2 | one of [`LAMPS`]; an unknown name warns and uses the default |
//!
//! Each lamp is the hue of its spectrum as LuxRender's film sees it ([`emission_hue`]: CIE 1931
//! over 380-720 nm, linear sRGB, luminance 1, like a `blackbody` texture; a light's gain sets
//! the brightness). The spectra are I. N. Galidakis's measurements (CC BY 3.0), which
//! LuxRender ships; only their hues are kept here, computed once from that data with
//! [`emission_hue`] (linear between samples, 0 outside them). As in LuxRender, the
//! incandescent lamps and the candle are blackbodies ([`BLACKBODY_LAMPS`]), their measured
//! data being poorly calibrated.

use super::common::Declared;
use glam::Vec3;

use super::constant::Constant;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::spectra::blackbody_rgb;
#[cfg(doc)]
use crate::spectra::emission_hue;

pub const DEFAULT_NAME: &str = "Incandescent2";

/// The lamps LuxRender renders as blackbodies, with their temperatures in kelvin.
pub const BLACKBODY_LAMPS: [(&str, f32); 3] = [
    ("Candle", 1020.0),
    ("Incandescent1", 2750.0),
    ("Incandescent2", 2900.0),
];

/// The other lamps and their hues (linear sRGB, luminance 1).
pub const LAMPS: [(&str, [f32; 3]); 64] = [
    ("Alcohol", [0.7362, 1.1647, 0.1450]),
    ("AntiInsect", [1.5094, 0.9495, 0.0000]),
    ("Ar", [1.5875, 0.7691, 1.5571]),
    ("BLAU", [1.0356, 0.8782, 2.1014]),
    ("BLNG", [0.0000, 1.1848, 2.1137]),
    ("BLP", [0.0000, 1.0565, 3.3850]),
    ("Butane", [0.6568, 1.1075, 0.9458]),
    ("CarbonArc", [1.2900, 0.9237, 0.9016]),
    ("Cd", [0.0000, 1.1032, 2.9224]),
    ("CFL27K", [1.6999, 0.8480, 0.4446]),
    ("CFL4K", [1.4167, 0.8353, 1.4043]),
    ("CFL6K", [1.1695, 0.9049, 1.4429]),
    ("CL42053", [0.0000, 1.2324, 1.6428]),
    ("CobaltGlass", [0.4920, 0.9785, 2.7090]),
    ("Daylight", [1.1529, 0.9473, 1.0714]),
    ("FeCo", [0.4435, 1.1256, 1.3947]),
    ("FL37K", [1.0251, 1.0009, 0.9177]),
    ("FLAV17K", [1.3458, 0.8398, 1.5685]),
    ("FLAV8K", [1.4155, 0.8208, 1.5513]),
    ("FLBL", [0.7859, 0.8206, 3.4076]),
    ("FLBLB", [0.9103, 0.2052, 9.1372]),
    ("FLD2", [1.0872, 0.9597, 1.1428]),
    ("GaPb", [1.3783, 0.8796, 1.0788]),
    ("GreenLaser", [0.0000, 1.3982, 0.0000]),
    ("GroLux", [1.9164, 0.7296, 0.9798]),
    ("GRUN", [0.9033, 1.1110, 0.1852]),
    ("HPM2", [0.9597, 1.0986, 0.1424]),
    ("HPMFL1", [1.4437, 0.8432, 1.2471]),
    ("HPMFL2", [1.5674, 0.7918, 1.3916]),
    ("HPMFL2Glow", [2.5755, 0.6192, 0.1333]),
    ("HPMFLCL42053", [0.0065, 1.2208, 1.7379]),
    ("HPMFLCobaltGlass", [0.5448, 0.9846, 2.4932]),
    ("HPMFLRedGlass", [2.6944, 0.5973, 0.0000]),
    ("HPMSB", [1.4154, 0.8698, 1.0664]),
    ("HPMSBFL", [1.5582, 0.8236, 1.1033]),
    ("HPS", [1.7580, 0.8091, 0.6587]),
    ("HPX", [0.8918, 1.0069, 1.2499]),
    ("LCDS", [1.5660, 0.8234, 1.0824]),
    ("LEDB", [0.0000, 0.8397, 5.5329]),
    ("LPM2", [0.6136, 0.9839, 2.2969]),
    ("LPS", [2.6160, 0.6206, 0.0000]),
    ("MHD", [1.3536, 0.8931, 1.0181]),
    ("MHN", [1.9227, 0.7715, 0.5468]),
    ("MHSc", [1.1474, 0.9503, 1.0584]),
    ("MHWWD", [1.4333, 0.8680, 1.0322]),
    ("MPS", [1.6438, 0.8959, 0.1358]),
    ("Ne", [3.3269, 0.4093, 0.0000]),
    ("NeKrFL", [0.9046, 1.1168, 0.1238]),
    ("NeXeFL1", [0.4477, 1.2530, 0.1199]),
    ("NeXeFL2", [1.3879, 0.7855, 1.9823]),
    ("OliveOil", [1.3241, 1.0046, 0.0000]),
    ("PLANTA", [1.7036, 0.7725, 1.1818]),
    ("Rb", [1.6366, 0.8399, 0.7115]),
    ("RedGlass", [3.1594, 0.4591, 0.0000]),
    ("RedLaser", [4.7037, 0.0000, 0.0000]),
    ("SHPS", [0.9742, 1.0121, 0.9563]),
    ("SS1", [1.5760, 0.9297, 0.0000]),
    ("SS2", [1.7952, 0.8646, 0.0000]),
    ("TV", [1.0549, 1.0173, 0.6666]),
    ("UVA", [0.9072, 1.1047, 0.2363]),
    ("Welsbach", [1.0587, 0.9969, 0.8582]),
    ("Xe", [0.7960, 1.1093, 0.5179]),
    ("XeI", [1.1386, 1.0064, 0.5280]),
    ("Zn", [2.1497, 0.4365, 3.1969]),
];

/// The hue of lamp `name`.
pub fn lamp(name: &str) -> Option<Vec3> {
    if let Some((_, kelvin)) = BLACKBODY_LAMPS.iter().find(|(n, _)| *n == name) {
        return Some(blackbody_rgb(*kelvin));
    }
    LAMPS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, rgb)| Vec3::from_array(*rgb))
}

pub fn read(
    _decl: &Declared,
    params: &ParamList,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<Constant, ParseError> {
    let name = params.string_or("name", DEFAULT_NAME)?;
    let value = lamp(&name).unwrap_or_else(|| {
        ctx.warn(
            pos,
            format!("lampspectrum: no lamp named \"{name}\"; using \"{DEFAULT_NAME}\""),
        );
        lamp(DEFAULT_NAME).expect("the default lamp exists")
    });
    Ok(Constant { value })
}
