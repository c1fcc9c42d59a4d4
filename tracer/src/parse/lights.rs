//! `LightSource` and area-light emission, with LuxRender's power/efficacy normalisation: when
//! power x efficacy > 0, the gain is scaled so the light emits that many lumens.

use std::f32::consts::PI;

use glam::Vec3;

use super::builder::{AreaLightParams, Builder};
use super::context::ParseContext;
use super::params::ParamList;
use super::{ParseError, Pos};
use crate::desc::{AreaLightDesc, EnvMapDesc, LightDesc};
use crate::math::luminance;

/// `gain x power x efficacy / denominator` when that factor is positive and finite
/// (LuxRender's rule), else `gain`.
fn normalised_gain(gain: f32, power: f32, efficacy: f32, denominator: f32) -> f32 {
    let factor = power * efficacy / denominator;
    if factor > 0.0 && factor.is_finite() {
        gain * factor
    } else {
        gain
    }
}

/// An area light's radiance for a shape of world-space area `area`.
pub fn area_light(e: &AreaLightParams, area: f32) -> AreaLightDesc {
    let gain = normalised_gain(e.gain, e.power, e.efficacy, area * PI * luminance(e.l));
    AreaLightDesc {
        radiance: e.l * gain,
    }
}

impl Builder<'_> {
    pub(super) fn light(
        &mut self,
        ty: &str,
        params: &ParamList,
        pos: &Pos,
    ) -> Result<(), ParseError> {
        let l = params.color("L", Vec3::ONE)?;
        let gain = params.float("gain", 1.0)?;
        let light = match ty {
            "point" | "goniometric" => {
                let from = params.vec3("from", Vec3::ZERO)?;
                let gain = normalised_gain(
                    gain,
                    params.float("power", 0.0)?,
                    params.float("efficacy", 0.0)?,
                    4.0 * PI * luminance(l),
                );
                // LuxRender translates by `from` after the light's transform.
                LightDesc::Point {
                    position: from + self.ctm.transform_point3(Vec3::ZERO),
                    intensity: l * gain,
                }
            }
            "spot" => {
                let from = params.vec3("from", Vec3::ZERO)?;
                let to = params.vec3("to", Vec3::Z)?;
                let cone_angle = params.float("coneangle", 30.0)?;
                let cone_delta_angle = params.float("conedeltaangle", 5.0)?;
                let Some(direction) = self.ctm.transform_vector3(to - from).try_normalize() else {
                    return Err(ParseError::Invalid {
                        pos: pos.clone(),
                        message: "LightSource \"spot\": \"from\" and \"to\" must differ".into(),
                    });
                };
                let cos_total = cone_angle.to_radians().cos();
                let cos_falloff_start = (cone_angle - cone_delta_angle).to_radians().cos();
                let gain = normalised_gain(
                    gain,
                    params.float("power", 0.0)?,
                    params.float("efficacy", 0.0)?,
                    2.0 * PI * luminance(l) * (1.0 - 0.5 * (cos_falloff_start + cos_total)),
                );
                LightDesc::Spot {
                    position: self.ctm.transform_point3(from),
                    direction,
                    intensity: l * gain,
                    cone_angle,
                    cone_delta_angle,
                }
            }
            "distant" => {
                let from = params.vec3("from", Vec3::ZERO)?;
                let to = params.vec3("to", Vec3::Z)?;
                if params.float("theta", 0.0)? != 0.0 {
                    self.warn(pos, "LightSource \"distant\": \"theta\" (a soft cone) is not supported; the light is a delta direction".into());
                }
                let Some(to_light) = self.ctm.transform_vector3(from - to).try_normalize() else {
                    return Err(ParseError::Invalid {
                        pos: pos.clone(),
                        message: "LightSource \"distant\": \"from\" and \"to\" must differ".into(),
                    });
                };
                LightDesc::Distant {
                    to_light,
                    radiance: l * gain,
                }
            }
            "infinite" | "infinitesample" => {
                let mapping = params.string_or("mapping", "latlong")?;
                if mapping != "latlong" {
                    self.warn(pos, format!("LightSource \"infinite\": mapping \"{mapping}\" is not supported; using latlong"));
                }
                let gamma = params.float("gamma", 1.0)?;
                let map = match params.string("mapname")? {
                    Some(filename) if !filename.is_empty() => {
                        self.check_image(&filename, pos)?;
                        Some(EnvMapDesc { filename, gamma })
                    }
                    _ => None,
                };
                LightDesc::Infinite {
                    radiance: l * gain,
                    map,
                    light_to_world: self.ctm,
                }
            }
            "sun" | "sky" | "sky2" | "sunsky" | "sunsky2" => {
                self.ignore_all(params);
                self.warn_once(
                    format!("light|{ty}"),
                    pos,
                    format!("LightSource \"{ty}\" is not supported; the light is skipped"),
                );
                return Ok(());
            }
            other => {
                self.ignore_all(params);
                self.warn(pos, format!("unknown LightSource \"{other}\" skipped"));
                return Ok(());
            }
        };
        self.lights.push(light);
        Ok(())
    }

    fn ignore_all(&self, params: &ParamList) {
        for p in &params.params {
            params.ignore(&p.name);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_gain_follows_power_and_efficacy() {
        let e = AreaLightParams {
            l: Vec3::new(1.0, 0.5, 0.25),
            gain: 2.0,
            power: 100.0,
            efficacy: 17.0,
        };
        let area = 0.5;
        let r = area_light(&e, area).radiance;
        let expected_gain = 2.0 * 100.0 * 17.0 / (area * PI * luminance(e.l));
        assert!((r - e.l * expected_gain).abs().max_element() < 1e-3 * expected_gain);
        // Emitted luminous power then equals gain x power x efficacy: Y(L x gain) x area x pi.
        assert!((luminance(r) * area * PI - 2.0 * 1700.0).abs() < 0.5);
        let off = AreaLightParams {
            power: 0.0,
            ..e.clone()
        };
        assert_eq!(area_light(&off, area).radiance, e.l * 2.0);
        // An infinite plane has no finite power: the gain stays as given.
        assert_eq!(area_light(&e, f32::INFINITY).radiance, e.l * 2.0);
    }
}
