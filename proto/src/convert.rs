//! Conversions between the wire messages and the tracer's types, with the checks a peer's
//! message must pass before anything is allocated from it.

use prost::bytes::{BufMut, Bytes, BytesMut};
use yat_tracer::desc::LatLongConvention;
use yat_tracer::film::{SampleBuffer, MAX_SUM};
use yat_tracer::render::unit::{FilmFrame, MAX_MASKED_SIDE};
use yat_tracer::render::{RenderSettings, UnitStats, WorkUnit};

use crate::pb;

/// Bytes per pixel in a sample buffer: RGB sums and the weight sum, four f32.
pub const BYTES_PER_PIXEL: usize = 16;

/// Largest unit a worker renders, in pixels of its tile: its reply (the tile and a border of at
/// most `MAX_BORDER` pixels) stays under 4.5 MiB, under every message limit.
pub const MAX_UNIT_PIXELS: u64 = 1 << 18;

/// More rays than any camera sample traces: a path has at most MAX_DEPTH (4096) scattering
/// vertices, each with one shadow ray and at most 64 pass-through vertices before it, about
/// 2^18 rays. A unit's ray count above this many per sample is a lie.
pub const MAX_RAYS_PER_SAMPLE: u64 = 1 << 20;

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
    #[error("asked for unit {asked}, got unit {got}")]
    OtherUnit { asked: u32, got: u32 },
    #[error("unit {index}: pixel {pixel} holds {value}, which {reason}")]
    PixelValue {
        index: u32,
        pixel: usize,
        value: f32,
        reason: &'static str,
    },
    #[error("unit {index}: {reason}")]
    Stats { index: u32, reason: String },
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
            block_mask: u.mask,
        }
    }
}

/// A unit of a render with these settings: a non-empty tile inside the image, a non-empty
/// sample range inside the pixel's samples, and at most [`MAX_UNIT_PIXELS`] pixels; with a
/// block mask, at most [`MAX_MASKED_SIDE`] a side and a non-zero mask of the tile's blocks.
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
    let unit = WorkUnit {
        index: u.index,
        x0: u.x0,
        y0: u.y0,
        x1: u.x1,
        y1: u.y1,
        sample_start: u.sample_start,
        sample_end: u.sample_end,
        mask: u.block_mask,
    };
    if let Some(mask) = u.block_mask {
        let (w, h) = (u.x1 - u.x0, u.y1 - u.y0);
        if w > MAX_MASKED_SIDE || h > MAX_MASKED_SIDE {
            return Err(invalid(format!(
                "a {w}x{h} tile with a block mask (at most {MAX_MASKED_SIDE} a side)"
            )));
        }
        let inside = unit.tile_blocks().fold(0, |all, (_, _, bit)| all | bit);
        if mask == 0 || mask & !inside != 0 {
            return Err(invalid(format!(
                "block mask {mask:#018x} is empty or names blocks outside the tile"
            )));
        }
    }
    Ok(unit)
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

/// The wire form of a sample buffer: per pixel of its region, r, g, b, weight as little-endian
/// f32 (for a masked unit once per source plane); then, for a masked unit, the same for its
/// odd-index samples.
pub fn encode_pixels(buffer: &SampleBuffer) -> Bytes {
    let len = buffer.weight.len() + buffer.half_weight.len();
    let mut out = BytesMut::with_capacity(len * BYTES_PER_PIXEL);
    let all = buffer.rgb.iter().zip(&buffer.weight);
    for (rgb, &weight) in all.chain(buffer.half_rgb.iter().zip(&buffer.half_weight)) {
        for v in rgb.iter().chain([&weight]) {
            out.put_f32_le(*v);
        }
    }
    out.freeze()
}

/// Bytes of a unit's sample buffer on the wire: its region of `frame` (the tile and the
/// filter's border), once per source plane and once more for a masked unit.
pub fn pixels_len(unit: &WorkUnit, frame: &FilmFrame) -> usize {
    let sums = if unit.mask.is_some() {
        frame.source_planes() + 1
    } else {
        1
    };
    frame.region(unit).pixel_count() * BYTES_PER_PIXEL * sums
}

/// Reads a sample buffer of `unit` back from its wire form, checking what an honest render can
/// produce: the length of its region of `frame` ([`pixels_len`]); finite values; sums
/// the film can hold (under [`MAX_SUM`], so one value cannot saturate it); weight sums no
/// larger than every sample that can reach the pixel weighing 1 (a sample gives each pixel a
/// weight of at most 1 in magnitude, see `filter.rs`: the unit's samples per pixel times the
/// pixels within the border, the odd half at most half of them, rounded up); zeros for the
/// pixels no sample of the unit reaches (beyond the border of the blocks a mask leaves on).
/// Radiance has no bound short of the film's: a bright but finite sum is indistinguishable from
/// a firefly. Negative sums are honest (filters with negative lobes weigh some samples
/// negatively).
pub fn decode_pixels(
    unit: WorkUnit,
    frame: &FilmFrame,
    bytes: &[u8],
) -> Result<SampleBuffer, WireError> {
    let expected = pixels_len(&unit, frame);
    if bytes.len() != expected {
        return Err(WireError::PixelsLength {
            index: unit.index,
            got: bytes.len(),
            expected,
        });
    }
    let [bx, by] = frame.border;
    let reach = f64::from(2 * bx + 1) * f64::from(2 * by + 1);
    let samples = f64::from(unit.sample_end - unit.sample_start) * reach;
    let odd = f64::from((unit.sample_end / 2).saturating_sub(unit.sample_start / 2)) * reach;
    let mut buffer = SampleBuffer::new(unit, frame);
    let region = buffer.region;
    let region_width = region.width() as usize;
    let n = region.pixel_count();
    for (pixel, px) in bytes.chunks_exact(BYTES_PER_PIXEL).enumerate() {
        let values: [f32; 4] =
            std::array::from_fn(|i| f32::from_le_bytes(px[4 * i..4 * i + 4].try_into().unwrap()));
        let refuse = |value: f32, reason| WireError::PixelValue {
            index: unit.index,
            pixel,
            value,
            reason,
        };
        for &value in &values {
            if !value.is_finite() {
                return Err(refuse(value, "is not finite"));
            }
            if value.abs() >= MAX_SUM {
                return Err(refuse(value, "exceeds what the film holds"));
            }
        }
        let half = pixel >= buffer.weight.len();
        let i = pixel % n;
        let max_weight = if half { odd } else { samples };
        if f64::from(values[3].abs()) > max_weight {
            return Err(refuse(
                values[3],
                "exceeds the unit's samples per pixel as a weight sum",
            ));
        }
        let (x, y) = (
            region.x0 + (i % region_width) as u32,
            region.y0 + (i / region_width) as u32,
        );
        if !unit.reaches(x, y, frame.border) && values.iter().any(|&v| v != 0.0) {
            return Err(refuse(
                values[3],
                "lies beyond the reach of the blocks the unit's mask leaves on",
            ));
        }
        let (rgb, weight, at) = if half {
            (&mut buffer.half_rgb, &mut buffer.half_weight, i)
        } else {
            (&mut buffer.rgb, &mut buffer.weight, pixel)
        };
        rgb[at] = [values[0], values[1], values[2]];
        weight[at] = values[3];
    }
    Ok(buffer)
}

/// A worker's reply to `unit`, checked: the unit's own index, a sample buffer that
/// [`decode_pixels`] accepts, and counters an honest render of the unit gives (exactly its
/// samples, no more dropped than taken, rays within [`MAX_RAYS_PER_SAMPLE`] per sample).
pub fn result_from_wire(
    unit: WorkUnit,
    frame: &FilmFrame,
    reply: &pb::RenderUnitReply,
) -> Result<(SampleBuffer, UnitStats), WireError> {
    if reply.index != unit.index {
        return Err(WireError::OtherUnit {
            asked: unit.index,
            got: reply.index,
        });
    }
    let buffer = decode_pixels(unit, frame, &reply.pixels)?;
    let stats = UnitStats::from(reply.stats.unwrap_or_default());
    let samples = unit.sample_count();
    let wrong = |reason: String| WireError::Stats {
        index: unit.index,
        reason,
    };
    if stats.samples != samples {
        return Err(wrong(format!(
            "{} samples reported, the unit has {samples}",
            stats.samples
        )));
    }
    if stats.dropped > samples {
        return Err(wrong(format!(
            "{} of {samples} samples reported dropped",
            stats.dropped
        )));
    }
    if stats.rays > samples.saturating_mul(MAX_RAYS_PER_SAMPLE) {
        return Err(wrong(format!(
            "{} rays reported for {samples} samples",
            stats.rays
        )));
    }
    Ok((buffer, stats))
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
            mask: None,
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
            mask: None,
        };
        let frame = FilmFrame::unbordered(3, 2);
        let buffer = SampleBuffer {
            unit,
            region: frame.region(&unit),
            rgb: (0..6)
                .map(|i| [i as f32 * 0.1, -0.0, f32::MIN_POSITIVE / (i + 1) as f32])
                .collect(),
            weight: (0..6).map(|i| 1.0 + i as f32 / 3.0).collect(),
            half_rgb: Vec::new(),
            half_weight: Vec::new(),
        };
        let bytes = encode_pixels(&buffer);
        assert_eq!(bytes.len(), 6 * BYTES_PER_PIXEL);
        let back = decode_pixels(unit, &frame, &bytes).unwrap();
        let bits = |b: &SampleBuffer| {
            b.rgb
                .iter()
                .flatten()
                .chain(&b.weight)
                .map(|v| v.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&back), bits(&buffer));
        assert!(decode_pixels(unit, &frame, &bytes[1..]).is_err());
    }

    /// A unit's buffer covers its tile and the filter's border, clipped to the film: the tile's
    /// length alone is refused, and so is a border's worth beyond what the film clips away.
    #[test]
    fn buffers_cover_the_border_clipped_to_the_film() {
        let unit = WorkUnit {
            index: 1,
            x0: 2,
            y0: 0,
            x1: 5,
            y1: 2,
            sample_start: 0,
            sample_end: 4,
            mask: None,
        };
        let frame = FilmFrame {
            width: 6,
            height: 8,
            border: [2, 1],
        };
        // Columns 0..6 (7 clipped to the film), rows 0..3 (-1 clipped).
        assert_eq!(pixels_len(&unit, &frame), 6 * 3 * BYTES_PER_PIXEL);
        let mut buffer = SampleBuffer::new(unit, &frame);
        // A corner pixel of the border: up to 4 samples from each of 5 x 3 pixels, weight < 1.
        buffer.rgb[2 * 6] = [1.0, 2.0, 3.0];
        buffer.weight[2 * 6] = 30.0;
        let bytes = encode_pixels(&buffer);
        assert_eq!(decode_pixels(unit, &frame, &bytes).unwrap(), buffer);
        let tile_only = 3 * 2 * BYTES_PER_PIXEL;
        assert!(decode_pixels(unit, &frame, &bytes[..tile_only]).is_err());
        let unclipped = FilmFrame {
            width: 100,
            ..frame
        };
        assert!(decode_pixels(unit, &unclipped, &bytes).is_err());
        // More weight than every sample within the border weighing 1 is a lie.
        buffer.weight[2 * 6] = 4.0 * 15.0 + 1.0;
        assert!(decode_pixels(unit, &frame, &encode_pixels(&buffer)).is_err());
    }

    #[test]
    fn masked_units_name_blocks_of_their_tile_and_carry_half_sums() {
        let s = RenderSettings {
            width: 100,
            spp: 64,
            ..settings()
        };
        // A 28x18 tile: 7 x 5 blocks (the last row 2 pixels tall); blocks (0, 0), (4, 0) and
        // (6, 4) on.
        let unit = WorkUnit {
            index: 2,
            x0: 72,
            y0: 0,
            x1: 100,
            y1: 18,
            sample_start: 16,
            sample_end: 21,
            mask: Some(1 | 1 << 4 | 1 << (4 * 8 + 6)),
        };
        assert_eq!(unit_from_wire(&(&unit).into(), &s).unwrap(), unit);
        // No mask, a block right of the tile, one below it, every bit.
        for mask in [0, 1 << 7, 1 << (5 * 8), u64::MAX] {
            let bad = WorkUnit {
                mask: Some(mask),
                ..unit
            };
            assert!(unit_from_wire(&(&bad).into(), &s).is_err(), "{mask:#x}");
        }
        let wide = WorkUnit {
            x0: 0,
            x1: MAX_MASKED_SIDE + 1,
            mask: Some(1),
            ..unit
        };
        assert!(unit_from_wire(&(&wide).into(), &s).is_err());

        // Samples 16..21: 5 in all, 2 odd (17, 19). Pixel (72, 0) is in block (0, 0), (97, 17)
        // in (6, 4), (78, 6) in no active block. Without a border a pixel gets only its own
        // block's samples: one source plane.
        let frame = FilmFrame::unbordered(s.width, s.height);
        let pixels = 28 * 18;
        let mut buffer = SampleBuffer::new(unit, &frame);
        assert_eq!(buffer.half_rgb.len(), pixels);
        assert_eq!(buffer.rgb.len(), pixels, "one plane");
        buffer.rgb[0] = [1.0, 2.0, 3.0];
        buffer.weight[0] = 5.0;
        buffer.rgb[17 * 28 + 25] = [4.0, 0.0, 0.0];
        buffer.weight[17 * 28 + 25] = 1.0;
        buffer.half_rgb[0] = [0.5, 1.0, 1.5];
        buffer.half_weight[0] = 2.0;
        let bytes = encode_pixels(&buffer);
        assert_eq!(bytes.len(), 2 * pixels * BYTES_PER_PIXEL);
        assert_eq!(decode_pixels(unit, &frame, &bytes).unwrap(), buffer);
        assert!(decode_pixels(unit, &frame, &bytes[..pixels * BYTES_PER_PIXEL]).is_err());
        let mut heavy_half = buffer.clone();
        heavy_half.half_weight[0] = 3.0;
        assert!(
            decode_pixels(unit, &frame, &encode_pixels(&heavy_half)).is_err(),
            "3 of 2 odd samples"
        );
        let mut outside = buffer.clone();
        outside.rgb[6 * 28 + 6] = [0.1, 0.0, 0.0];
        assert!(
            decode_pixels(unit, &frame, &encode_pixels(&outside)).is_err(),
            "a masked-out pixel"
        );

        // With a 2-pixel border, active blocks splat into their neighbours (in 4 source
        // planes): pixels within 2 of block (0, 0) may hold sums in any plane, those farther
        // from every active block may not.
        let frame = FilmFrame {
            border: [2, 2],
            ..frame
        };
        assert_eq!(frame.source_planes(), 4);
        let region = frame.region(&unit);
        assert_eq!(
            (region.x0, region.x1, region.y0, region.y1),
            (70, 100, 0, 20)
        );
        let at = |x: u32, y: u32| ((y - region.y0) * region.width() + x - region.x0) as usize;
        for plane in 0..4 {
            for (x, y, reached) in [
                (70, 3, true),
                (77, 5, true),
                (78, 3, false),
                (80, 10, false),
            ] {
                let mut buffer = SampleBuffer::new(unit, &frame);
                let i = plane * region.pixel_count() + at(x, y);
                buffer.rgb[i] = [0.1, 0.0, 0.0];
                buffer.weight[i] = 0.5;
                let decoded = decode_pixels(unit, &frame, &encode_pixels(&buffer));
                assert_eq!(decoded.is_ok(), reached, "({x}, {y}) in plane {plane}");
            }
        }
    }

    /// A 2x1 tile of 4 samples per pixel whose second pixel's values are `values`, encoded.
    fn reply_with(values: [f32; 4]) -> (WorkUnit, pb::RenderUnitReply) {
        let unit = WorkUnit {
            index: 5,
            x0: 0,
            y0: 0,
            x1: 2,
            y1: 1,
            sample_start: 4,
            sample_end: 8,
            mask: None,
        };
        let buffer = SampleBuffer {
            unit,
            region: FilmFrame::unbordered(2, 1).region(&unit),
            rgb: vec![[0.5, 0.25, 0.0], [values[0], values[1], values[2]]],
            weight: vec![4.0, values[3]],
            half_rgb: Vec::new(),
            half_weight: Vec::new(),
        };
        let reply = pb::RenderUnitReply {
            index: unit.index,
            pixels: encode_pixels(&buffer),
            stats: Some(pb::UnitStats {
                samples: 8,
                rays: 40,
                dropped: 0,
            }),
            render_seconds: 0.1,
        };
        (unit, reply)
    }

    #[test]
    fn honest_results_pass_including_negative_lobes_and_bright_pixels() {
        for values in [
            [1.0, 2.0, 3.0, 4.0],
            [-0.5, -0.1, 0.0, -2.0],
            [0.0, 0.0, 0.0, -4.0],
            [1e9, 3e10, 0.0, 1.0],
            [-0.0, f32::MIN_POSITIVE, 0.0, 0.0],
        ] {
            let (unit, reply) = reply_with(values);
            let (buffer, stats) =
                result_from_wire(unit, &FilmFrame::unbordered(2, 1), &reply).unwrap();
            assert_eq!(buffer.rgb[1], [values[0], values[1], values[2]]);
            assert_eq!(buffer.weight[1], values[3]);
            assert_eq!(stats.samples, 8);
        }
    }

    #[test]
    fn non_finite_huge_or_impossible_values_are_refused() {
        for values in [
            [f32::NAN, 0.0, 0.0, 1.0],
            [0.0, f32::INFINITY, 0.0, 1.0],
            [0.0, 0.0, f32::NEG_INFINITY, 1.0],
            [0.0, 0.0, 0.0, f32::NAN],
            [f32::MAX, 0.0, 0.0, 1.0],
            [0.0, -1e12, 0.0, 1.0],
            [MAX_SUM, 0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0, 5.0],
            [1.0, 1.0, 1.0, -4.5],
            [1.0, 1.0, 1.0, 1e30],
        ] {
            let (unit, reply) = reply_with(values);
            let error = result_from_wire(unit, &FilmFrame::unbordered(2, 1), &reply).unwrap_err();
            assert!(
                matches!(
                    error,
                    WireError::PixelValue {
                        index: 5,
                        pixel: 1,
                        ..
                    }
                ),
                "{values:?}: {error}"
            );
        }
    }

    #[test]
    fn another_units_reply_or_false_counters_are_refused() {
        let (unit, reply) = reply_with([0.0; 4]);
        let other = pb::RenderUnitReply {
            index: 6,
            ..reply.clone()
        };
        assert!(matches!(
            result_from_wire(unit, &FilmFrame::unbordered(2, 1), &other),
            Err(WireError::OtherUnit { asked: 5, got: 6 })
        ));
        let short = pb::RenderUnitReply {
            pixels: reply.pixels.slice(..16),
            ..reply.clone()
        };
        assert!(matches!(
            result_from_wire(unit, &FilmFrame::unbordered(2, 1), &short),
            Err(WireError::PixelsLength { .. })
        ));
        for (samples, rays, dropped) in [(7, 40, 0), (9, 40, 0), (8, 40, 9), (8, u64::MAX, 0)] {
            let lying = pb::RenderUnitReply {
                stats: Some(pb::UnitStats {
                    samples,
                    rays,
                    dropped,
                }),
                ..reply.clone()
            };
            assert!(
                matches!(
                    result_from_wire(unit, &FilmFrame::unbordered(2, 1), &lying),
                    Err(WireError::Stats { .. })
                ),
                "{samples} {rays} {dropped}"
            );
        }
        let without_stats = pb::RenderUnitReply {
            stats: None,
            ..reply
        };
        assert!(result_from_wire(unit, &FilmFrame::unbordered(2, 1), &without_stats).is_err());
    }
}
