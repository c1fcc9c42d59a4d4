//! `--latlong`: how LatLong environment maps are indexed (`yat render`, `yat export-luxcore`).

use yat_tracer::desc::LatLongConvention;

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum LatLongArg {
    /// The course tracer's u = (pi + phi) / 2pi: seed scenes look as their authors made them.
    Seed,
    /// LuxRender's s = phi / 2pi, for scenes made in LuxRender.
    Luxrender,
}

impl From<LatLongArg> for LatLongConvention {
    fn from(arg: LatLongArg) -> Self {
        match arg {
            LatLongArg::Seed => LatLongConvention::Seed,
            LatLongArg::Luxrender => LatLongConvention::LuxRender,
        }
    }
}
