//! Conversions between the wire messages and the tracer's types, with the checks a peer's
//! message must pass before anything is allocated from it.

use prost::bytes::{BufMut, Bytes, BytesMut};
use yat_tracer::desc::LatLongConvention;
use yat_tracer::film::SampleBuffer;
use yat_tracer::render::{RenderSettings, UnitStats, WorkUnit};

use crate::pb;

/// Bytes per pixel in a sample buffer: RGB sums and the weight sum, four f32.
pub const BYTES_PER_PIXEL: usize = 16;

/// Largest unit a worker renders: its reply stays at 4 MiB, under every message limit.
pub const MAX_UNIT_PIXELS: u64 = 1 << 18;

#[derive(Debug, thiserror::Error)]
pub enum WireError {
    #[error("the request lacks its {0}")]
    Missing(&'static str),
    #[error("invalid render settings: {0}")]
    Settings(String),
    #[error("invalid work unit {index}: {reason}")]
    Unit { index: u32, reason: String },
    #[error("unit {index}: the sample buffer has {got} bytes, {expected} expected")]
    PixelsLength {
        index: u32,
        got: usize,
        expected: usize,
    },
}

impl From<&RenderSettings> for pb::RenderSettings {
    fn from(s: &RenderSettings) -> Self {
        let latlong = match s.latlong {
            LatLongConvention::Seed => pb::LatLongConvention::LatlongSeed,
            LatLongConvention::LuxRender => pb::LatLongConvention::LatlongLuxrender,
        };
        Self {
            width: s.width,
            height: s.height,
            spp: s.spp,
            max_depth: s.max_depth,
            seed: s.seed,
            latlong: latlong.into(),
        }
    }
}

impl TryFrom<&pb::RenderSettings> for RenderSettings {
    type Error = WireError;

    fn try_from(s: &pb::RenderSettings) -> Result<Self, WireError> {
        let latlong = match pb::LatLongConvention::try_from(s.latlong) {
            Ok(pb::LatLongConvention::LatlongSeed) => LatLongConvention::Seed,
            Ok(pb::LatLongConvention::LatlongLuxrender) => LatLongConvention::LuxRender,
            Err(_) => {
                return Err(WireError::Settings(format!(
                    "unknown latlong convention {}",
                    s.latlong
                )))
            }
        };
        let settings = Self {
            width: s.width,
            height: s.height,
            spp: s.spp,
            max_depth: s.max_depth,
            seed: s.seed,
            latlong,
        };
        settings
            .check()
            .map_err(|e| WireError::Settings(e.to_string()))?;
        Ok(settings)
    }
}

impl From<&WorkUnit> for pb::WorkUnit {
    fn from(u: &WorkUnit) -> Self {
        Self {
            index: u.index,
            x0: u.x0,
            y0: u.y0,
            x1: u.x1,
            y1: u.y1,
            sample_start: u.sample_start,
            sample_end: u.sample_end,
        }
    }
}

/// A unit of a render with these settings: a non-empty tile inside the image, a non-empty
/// sample range inside the pixel's samples, and at most [`MAX_UNIT_PIXELS`] pixels.
pub fn unit_from_wire(u: &pb::WorkUnit, settings: &RenderSettings) -> Result<WorkUnit, WireError> {
    let invalid = |reason: String| WireError::Unit {
        index: u.index,
        reason,
    };
    if !(u.x0 < u.x1 && u.x1 <= settings.width && u.y0 < u.y1 && u.y1 <= settings.height) {
        return Err(invalid(format!(
            "tile [{}, {}) x [{}, {}) is empty or outside the {}x{} image",
            u.x0, u.x1, u.y0, u.y1, settings.width, settings.height
        )));
    }
    if !(u.sample_start < u.sample_end && u.sample_end <= settings.spp) {
        return Err(invalid(format!(
            "sample range [{}, {}) is empty or beyond {} spp",
            u.sample_start, u.sample_end, settings.spp
        )));
    }
    let pixels = u64::from(u.x1 - u.x0) * u64::from(u.y1 - u.y0);
    if pixels > MAX_UNIT_PIXELS {
        return Err(invalid(format!("{pixels} pixels exceed {MAX_UNIT_PIXELS}")));
    }
    Ok(WorkUnit {
        index: u.index,
        x0: u.x0,
        y0: u.y0,
        x1: u.x1,
        y1: u.y1,
        sample_start: u.sample_start,
        sample_end: u.sample_end,
    })
}

impl From<UnitStats> for pb::UnitStats {
    fn from(s: UnitStats) -> Self {
        Self {
            samples: s.samples,
            rays: s.rays,
            dropped: s.dropped,
        }
    }
}

impl From<pb::UnitStats> for UnitStats {
    fn from(s: pb::UnitStats) -> Self {
        Self {
            samples: s.samples,
            rays: s.rays,
            dropped: s.dropped,
        }
    }
}

/// The wire form of a sample buffer: per pixel, r, g, b, weight as little-endian f32.
pub fn encode_pixels(buffer: &SampleBuffer) -> Bytes {
    let mut out = BytesMut::with_capacity(buffer.weight.len() * BYTES_PER_PIXEL);
    for (rgb, &weight) in buffer.rgb.iter().zip(&buffer.weight) {
        for v in rgb.iter().chain([&weight]) {
            out.put_f32_le(*v);
        }
    }
    out.freeze()
}

/// Reads a sample buffer of `unit` back from its wire form; the length must match the tile.
pub fn decode_pixels(unit: WorkUnit, bytes: &[u8]) -> Result<SampleBuffer, WireError> {
    let expected = unit.pixel_count() * BYTES_PER_PIXEL;
    if bytes.len() != expected {
        return Err(WireError::PixelsLength {
            index: unit.index,
            got: bytes.len(),
            expected,
        });
    }
    let mut rgb = Vec::with_capacity(unit.pixel_count());
    let mut weight = Vec::with_capacity(unit.pixel_count());
    for px in bytes.chunks_exact(BYTES_PER_PIXEL) {
        let f = |i: usize| f32::from_le_bytes(px[4 * i..4 * i + 4].try_into().unwrap());
        rgb.push([f(0), f(1), f(2)]);
        weight.push(f(3));
    }
    Ok(SampleBuffer { unit, rgb, weight })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> RenderSettings {
        RenderSettings {
            width: 100,
            height: 50,
            spp: 16,
            max_depth: 5,
            seed: 7,
            latlong: LatLongConvention::LuxRender,
        }
    }

    #[test]
    fn settings_round_trip_and_reject_empty_images() {
        let s = settings();
        assert_eq!(
            RenderSettings::try_from(&pb::RenderSettings::from(&s)).unwrap(),
            s
        );
        let mut wire = pb::RenderSettings::from(&s);
        wire.height = 0;
        assert!(RenderSettings::try_from(&wire).is_err());
        wire.height = 1 << 20;
        wire.width = 1 << 20;
        assert!(RenderSettings::try_from(&wire).is_err());
        wire = pb::RenderSettings::from(&s);
        wire.latlong = 9;
        assert!(RenderSettings::try_from(&wire).is_err());
    }

    #[test]
    fn units_must_lie_inside_the_render() {
        let s = settings();
        let unit = WorkUnit {
            index: 3,
            x0: 64,
            y0: 0,
            x1: 100,
            y1: 50,
            sample_start: 8,
            sample_end: 16,
        };
        assert_eq!(unit_from_wire(&(&unit).into(), &s).unwrap(), unit);
        for bad in [
            WorkUnit { x1: 101, ..unit },
            WorkUnit { x1: 64, ..unit },
            WorkUnit { y0: 50, ..unit },
            WorkUnit {
                sample_end: 17,
                ..unit
            },
            WorkUnit {
                sample_start: 16,
                ..unit
            },
        ] {
            assert!(unit_from_wire(&(&bad).into(), &s).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn pixels_round_trip_bit_exactly() {
        let unit = WorkUnit {
            index: 1,
            x0: 0,
            y0: 0,
            x1: 3,
            y1: 2,
            sample_start: 0,
            sample_end: 4,
        };
        let buffer = SampleBuffer {
            unit,
            rgb: (0..6)
                .map(|i| [i as f32 * 0.1, -0.0, f32::MIN_POSITIVE / (i + 1) as f32])
                .collect(),
            weight: (0..6).map(|i| 1.0 + i as f32 / 3.0).collect(),
        };
        let bytes = encode_pixels(&buffer);
        assert_eq!(bytes.len(), 6 * BYTES_PER_PIXEL);
        let back = decode_pixels(unit, &bytes).unwrap();
        let bits = |b: &SampleBuffer| {
            b.rgb
                .iter()
                .flatten()
                .chain(&b.weight)
                .map(|v| v.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&back), bits(&buffer));
        assert!(decode_pixels(unit, &bytes[1..]).is_err());
    }
}
