//! Parameters that exporters write on statements whose LuxRender 1.x plugin never reads them
//! (checked in LuxRender's source): YAT ignores them as LuxRender does, so the image is the
//! same and `yat check` lists them as notes rather than as differences. Any other parameter
//! YAT does not read may be one LuxRender reads, and is reported as a difference.

/// Whether LuxRender's plugin for `statement` (as labelled in a parameter list, e.g.
/// `Material "mirror"`) ignores parameter `name`.
pub fn luxrender_ignores(statement: &str, name: &str) -> bool {
    matches!(
        (statement, name),
        // LuxRender's mirror reads Kr, film, filmindex and bumpmap only; LuxBlend writes a
        // mirror's glass-like index and a diffuse colour anyway.
        ("Material \"mirror\"", "index" | "Kd")
            // pbrt's plastic and shinymetal had one `roughness`; LuxRender 1.x reads
            // uroughness and vroughness only (their defaults apply).
            | ("Material \"plastic\"" | "Material \"shinymetal\"", "roughness")
            // Only LuxRender's glass has a thin film; its roughglass and glass2 read neither.
            | ("Material \"roughglass\"" | "Material \"glass2\"", "film" | "filmindex")
    )
}
