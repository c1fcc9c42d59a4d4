//! Materials and their BSDFs: matte (Oren-Nayar), glossy (Glossy2), mirror, glass and rough
//! glass, metal/metal2 (microfacet conductor), mattetranslucent, null, mix.
//!
//! A material is resolved per hit into a [`Bsdf`]: textures are evaluated at the hit, `mix`
//! materials are resolved stochastically, and the result is a plain value.

mod bsdf;
mod bxdf;
mod conductor;
mod dielectric;
mod diffuse;
mod fresnel;
mod ggx_albedo;
mod glossy;
mod local;
mod microfacet;

#[cfg(test)]
mod tests;

use glam::Vec3;

pub use bsdf::{Bsdf, BsdfSample};

use crate::desc::{MaterialDesc, SceneDesc};

use crate::geometry::SurfaceHit;
use crate::math::Frame;
use crate::param::{Fresnel, MaterialId, Tex};
use crate::texture::{TexturePoint, Textures};
use bxdf::Bxdf;
use conductor::{Conductor, ConductorFresnel};
use dielectric::{Dielectric, Surface};
use diffuse::{DiffuseReflection, DiffuseTranslucent, OrenNayar};
use glossy::Glossy;
use microfacet::TrowbridgeReitz;

/// What a hit on an undefined material (an out-of-range id, or a mix cycle) shows: LuxRender's
/// default matte.
const DEFAULT_MATTE_KD: f32 = 0.9;

pub struct Materials {
    materials: Vec<MaterialDesc>,
}

/// Reflectances are clamped to [0, 1] (as LuxRender does) so no texture can create energy;
/// NaN becomes 0.
fn unit(c: Vec3) -> Vec3 {
    c.max(Vec3::ZERO).min(Vec3::ONE)
}

impl Materials {
    pub fn build(desc: &SceneDesc) -> Self {
        Self::new(desc.materials.clone())
    }

    /// The materials indexed by [`MaterialId`].
    pub fn new(materials: Vec<MaterialDesc>) -> Self {
        let multibounce = materials.iter().any(|m| {
            matches!(
                m,
                MaterialDesc::Glossy {
                    multibounce: true,
                    ..
                }
            )
        });
        if multibounce {
            ggx_albedo::prepare();
        }
        Self { materials }
    }

    /// Follows `mix` materials down to a leaf. At each level `u_mix` chooses a side against
    /// the amount and is rescaled to [0, 1) within the chosen side, so nested mixes draw on
    /// the same number without correlation between levels.
    fn resolve(
        &self,
        id: MaterialId,
        at: &TexturePoint,
        textures: &Textures,
        u_mix: f32,
    ) -> Option<&MaterialDesc> {
        let mut material = self.materials.get(id.0 as usize)?;
        let mut u = u_mix;
        // A well-formed scene cannot nest deeper than it has materials; more means a cycle.
        for _ in 0..=self.materials.len() {
            let MaterialDesc::Mix { a, b, amount } = material else {
                return Some(material);
            };
            let amount = textures.eval(*amount, at).x.clamp(0.0, 1.0);
            let next = if u < amount {
                u /= amount;
                b
            } else {
                u = (u - amount) / (1.0 - amount);
                a
            };
            u = u.clamp(0.0, 1.0 - f32::EPSILON);
            material = self.materials.get(next.0 as usize)?;
        }
        Some(material)
    }

    /// The BSDF of material `id` at `hit`, whose position in its shape's object space is
    /// `p_object` (what 3D texture mappings see). `u_mix` resolves `mix` materials
    /// stochastically.
    pub fn bsdf(
        &self,
        id: MaterialId,
        hit: &SurfaceHit,
        p_object: Vec3,
        textures: &Textures,
        u_mix: f32,
    ) -> Bsdf {
        let at = TexturePoint {
            p: p_object,
            uv: hit.uv,
        };
        let color = |t: Tex| unit(textures.eval(t, &at));
        let float = |t: Tex| textures.eval(t, &at).x;
        let roughness = |u: Tex, v: Tex| TrowbridgeReitz::from_roughness(float(u), float(v));

        let bxdf = match self.resolve(id, &at, textures, u_mix) {
            // A dangling id or a mix cycle (resolve gives up on it).
            None | Some(MaterialDesc::Mix { .. }) => Bxdf::Diffuse(DiffuseReflection {
                r: Vec3::splat(DEFAULT_MATTE_KD),
                roughness: OrenNayar::new(0.0),
            }),
            Some(&MaterialDesc::Matte { kd, sigma }) => Bxdf::Diffuse(DiffuseReflection {
                r: color(kd),
                roughness: OrenNayar::new(float(sigma)),
            }),
            Some(&MaterialDesc::MatteTranslucent { kr, kt, sigma }) => {
                let r = color(kr);
                // LuxRender's "energyconserving" rule, always on: what is reflected cannot
                // also be transmitted.
                let t = color(kt) * (Vec3::ONE - r);
                Bxdf::Translucent(DiffuseTranslucent {
                    r,
                    t,
                    roughness: OrenNayar::new(float(sigma)),
                })
            }
            Some(&MaterialDesc::Glossy {
                kd,
                ks,
                ka,
                depth,
                uroughness,
                vroughness,
                multibounce,
            }) => {
                let distrib = roughness(uroughness, vroughness);
                let multibounce_alpha = match (multibounce, distrib) {
                    (true, Some(_)) => {
                        let (u, v) = (float(uroughness), float(vroughness));
                        Some((u.max(0.0) * v.max(0.0)).sqrt().clamp(0.0, 1.0))
                    }
                    _ => None,
                };
                Bxdf::Glossy(Glossy {
                    kd: color(kd),
                    ks: color(ks),
                    ka: color(ka),
                    depth: float(depth).max(0.0),
                    distrib,
                    multibounce_alpha,
                })
            }
            Some(&MaterialDesc::Mirror { kr }) => Bxdf::Conductor(Conductor {
                fresnel: ConductorFresnel::Constant(color(kr)),
                distrib: None,
            }),
            Some(&MaterialDesc::Glass {
                kr,
                kt,
                index,
                architectural,
                uroughness,
                vroughness,
            }) => {
                let eta = float(index);
                let surface = if architectural {
                    Surface::Thin
                } else {
                    match roughness(uroughness, vroughness) {
                        Some(distrib) => Surface::Rough(distrib),
                        None => Surface::Smooth,
                    }
                };
                Bxdf::Dielectric(Dielectric {
                    kr: color(kr),
                    kt: color(kt),
                    // A non-positive index is meaningless; treat it as no interface.
                    eta: if eta > 0.0 { eta } else { 1.0 },
                    surface,
                })
            }
            Some(MaterialDesc::Metal {
                fresnel,
                uroughness,
                vroughness,
            }) => {
                let fresnel = match *fresnel {
                    Fresnel::Conductor { eta, k } => ConductorFresnel::Complex { eta, k },
                    Fresnel::Index(index) => ConductorFresnel::Complex {
                        eta: Vec3::splat(float(index).max(1e-3)),
                        k: Vec3::ZERO,
                    },
                    Fresnel::Reflectance(r0) => ConductorFresnel::Schlick { r0: color(r0) },
                };
                Bxdf::Conductor(Conductor {
                    fresnel,
                    distrib: roughness(*uroughness, *vroughness),
                })
            }
            Some(MaterialDesc::Null) => Bxdf::PassThrough,
        };
        Bsdf::new(Frame::from_normal_tangent(hit.ns, hit.dpdu), hit.ng, bxdf)
    }
}
