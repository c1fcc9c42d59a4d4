//! The choices an export leaves to the caller.

use yat_tracer::desc::LatLongConvention;

/// Segments around a tessellated shape when the caller does not say.
pub const DEFAULT_SEGMENTS: u32 = 256;

#[derive(Clone, Debug)]
pub struct ExportOptions {
    /// How YAT indexes LatLong maps for this render; the export turns LuxCore's map to match.
    pub latlong: LatLongConvention,
    /// Segments around a tessellated sphere, disk or cylinder (half as many from pole to pole).
    pub segments: u32,
}

impl Default for ExportOptions {
    fn default() -> Self {
        Self {
            latlong: LatLongConvention::default(),
            segments: DEFAULT_SEGMENTS,
        }
    }
}
