//! The scattering functions in the local shading frame (z = shading normal), one variant per
//! lobe, dispatched by match (no heap, no virtual calls). Materials (crate::material) build
//! them per hit from their evaluated parameters; [`bsdf::Bsdf`] places one in the world (it
//! imports this enum; nothing here imports it).
//!
//! Files: [`sample`] (the shared [`LocalSample`]), [`lobe`] (the [`Lobe`] trait every lobe
//! implements), [`local`] (local-frame helpers), [`fresnel`], [`microfacet`]
//! (Trowbridge-Reitz/GGX), [`ggx_albedo`] (multiple-scattering tables), [`thin_film`]
//! (interference on specular reflections), the lobes
//! [`pass_through`], [`diffuse`], [`translucent`], [`conductor`], [`dielectric`], [`velvet`], [`scatter`],
//! [`cloth`], [`fresnel_blend`], the glossy [`coat`] layer and [`coat_over_base`] (a coat over any base lobe), and [`bsdf`]
//! (world frame). A new lobe is its file (its struct and [`Lobe`] impl) plus one line in the
//! lobe list below.

pub mod bsdf;
pub mod coat;
pub mod coat_over_base;
pub mod fresnel;
pub mod ggx_albedo;
pub mod lobe;
pub mod local;
pub mod microfacet;
pub mod sample;
pub mod thin_film;

use glam::{Vec2, Vec3};

pub use conductor::GLOSSY_ALPHA;
pub use lobe::Lobe;
pub use sample::LocalSample;

use local::flip_z;

/// Generates the lobe family from its list (see [`lobes!`]'s invocation below): each lobe's
/// module, the [`Bxdf`] variant and every dispatch `match`, each arm a call of the lobe's
/// [`Lobe`] method (a plain match: no heap, no virtual calls).
macro_rules! lobes {
    ($($(#[$doc:meta])* $variant:ident($module:ident::$lobe:ident),)+) => {
        $(pub mod $module;)+

        #[derive(Clone, Copy, Debug)]
        pub enum Bxdf {
            $($(#[$doc])* $variant($module::$lobe),)+
        }

        impl Bxdf {
            /// Whether the lobe is a delta distribution (light samples never find it).
            pub fn is_specular(&self) -> bool {
                match self {
                    $(Bxdf::$variant(l) => l.is_specular(),)+
                }
            }

            /// Whether the lobe reflects only (light reaches the surface from the side it is
            /// seen from) and spreads over the hemisphere much as the cosine does: the surfaces
            /// whose light samples of an environment map are drawn for the side they face. A
            /// metal's lobe is narrower: most of those samples would find it dark, each after a
            /// shadow ray, where half of the map's own samples fall behind the surface at no
            /// cost.
            pub fn gathers_broadly(&self) -> bool {
                match self {
                    $(Bxdf::$variant(_) => <$module::$lobe as Lobe>::GATHERS_BROADLY,)+
                }
            }

            /// For a rough metal whose lobe is narrow (alpha below [`GLOSSY_ALPHA`]), the half
            /// angle around the mirror direction that holds most of its lobe: a lamp it
            /// reflects is a bright, sharp-edged patch of the lobe, which one BSDF sample finds
            /// or misses.
            pub fn glossy_spread(&self) -> Option<f32> {
                match self {
                    $(Bxdf::$variant(l) => l.glossy_spread(),)+
                }
            }

            /// Roughly what the lobe reflects and transmits of the light arriving at `cos_o`:
            /// what a coat over it weighs it by when choosing which to sample.
            pub fn albedo_hint(&self, cos_o: f32) -> Vec3 {
                match self {
                    $(Bxdf::$variant(l) => l.albedo_hint(cos_o),)+
                }
            }

            /// Whether a query from `wo` is mirrored to the upper hemisphere (see
            /// [`Lobe::TWO_SIDED`]).
            fn mirrors_back_face(&self, wo: Vec3) -> bool {
                wo.z < 0.0
                    && match self {
                        $(Bxdf::$variant(_) => <$module::$lobe as Lobe>::TWO_SIDED,)+
                    }
            }

            /// `wo` and `wi` as the lobe handles them: mirrored together when `wo` is below a
            /// two-sided lobe.
            fn facing_up(&self, wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
                if self.mirrors_back_face(wo) {
                    (flip_z(wo), flip_z(wi))
                } else {
                    (wo, wi)
                }
            }

            pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
                let (wo, wi) = self.facing_up(wo, wi);
                match self {
                    $(Bxdf::$variant(l) => l.f(wo, wi),)+
                }
            }

            pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
                let (wo, wi) = self.facing_up(wo, wi);
                match self {
                    $(Bxdf::$variant(l) => l.pdf(wo, wi),)+
                }
            }

            pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
                let mirrored = self.mirrors_back_face(wo);
                let wo = if mirrored { flip_z(wo) } else { wo };
                let sample = match self {
                    $(Bxdf::$variant(l) => l.sample(wo, u_lobe, u),)+
                }?;
                Some(if mirrored {
                    LocalSample {
                        wi: flip_z(sample.wi),
                        ..sample
                    }
                } else {
                    sample
                })
            }
        }
    };
}

// The lobes: `Variant(module::Lobe),`.
lobes! {
    /// `null`: not a surface at all.
    PassThrough(pass_through::PassThrough),
    Diffuse(diffuse::DiffuseReflection),
    Translucent(translucent::DiffuseTranslucent),
    Conductor(conductor::Conductor),
    Dielectric(dielectric::Dielectric),
    Velvet(velvet::Velvet),
    Scatter(scatter::Scatter),
    Cloth(cloth::Cloth),
    /// glossy_lossy (substrate, plastic).
    FresnelBlend(fresnel_blend::FresnelBlend),
}
