//! Conversions between the wire messages and the tracer's types, with the checks a peer's
//! message must pass before anything is allocated from it.

use std::ops::Range;

use prost::bytes::{BufMut, Bytes, BytesMut};
use yat_tracer::desc::LatLongConvention;
use yat_tracer::film::{LightSplats, SampleBuffer, MAX_SPLAT_PIXELS, MAX_SUM};
use yat_tracer::filter::WeightBounds;
use yat_tracer::integrator::Transport;
use yat_tracer::render::layers::{Aovs, SumKind};
use yat_tracer::render::unit::{FilmFrame, PixelRect, BLOCK_SIZE, MAX_MASKED_SIDE};
use yat_tracer::render::{RenderSettings, UnitStats, WorkUnit};

use crate::pb;

/// Bytes per pixel in a sample buffer: RGB sums and the weight sum, four f32.
pub const BYTES_PER_PIXEL: usize = 16;

/// Bytes per light splat pixel on the wire: its index (u32) and its RGB sums (three f32).
pub const BYTES_PER_SPLAT: usize = 16;

/// Bytes per layer sum of a pixel on the wire (alpha's: one f32).
pub const BYTES_PER_LAYER_SUM: usize = 4;

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
    #[error("unit {index}: the layers take {got} bytes, {expected} expected")]
    LayersLength {
        index: u32,
        got: usize,
        expected: usize,
    },
    #[error("unit {index}: layer sum {at} holds {value}, which {reason}")]
    LayerValue {
        index: u32,
        at: usize,
        value: f32,
        reason: &'static str,
    },
    #[error("unit {index}: the light splats take {got} bytes, not a whole number of {BYTES_PER_SPLAT}-byte pixels up to {max} pixels")]
    SplatsLength { index: u32, got: usize, max: usize },
    #[error("unit {index}: {misfit}")]
    Splats {
        index: u32,
        misfit: yat_tracer::film::SplatMisfit,
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
            transport: match s.transport {
                Transport::Path => pb::Transport::Path,
                Transport::Bidirectional => pb::Transport::Bidirectional,
                Transport::DirectLighting => pb::Transport::DirectLighting,
            }
            .into(),
            aovs: s.aovs.bits(),
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
        let transport = match pb::Transport::try_from(s.transport) {
            Ok(pb::Transport::Path) => Transport::Path,
            Ok(pb::Transport::Bidirectional) => Transport::Bidirectional,
            Ok(pb::Transport::DirectLighting) => Transport::DirectLighting,
            Err(_) => {
                return Err(WireError::Settings(format!(
                    "unknown transport {}",
                    s.transport
                )))
            }
        };
        let aovs = Aovs::from_bits(s.aovs)
            .ok_or_else(|| WireError::Settings(format!("unknown AOV bits {:#x}", s.aovs)))?;
        let settings = Self {
            width: s.width,
            height: s.height,
            spp: s.spp,
            max_depth: s.max_depth,
            seed: s.seed,
            latlong,
            transport,
            aovs,
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

/// The wire form of a sample buffer's layer sums: little-endian f32 in the buffer's order (per
/// source plane, per pixel of the region, per layer); empty when the film keeps no layer.
pub fn encode_layers(buffer: &SampleBuffer) -> Bytes {
    let mut out = BytesMut::with_capacity(buffer.layers.len() * BYTES_PER_LAYER_SUM);
    buffer.layers.iter().for_each(|&v| out.put_f32_le(v));
    out.freeze()
}

/// Bytes of a unit's layer sums on the wire: its region of `frame`, once per source plane for a
/// masked unit, times the frame's layer sums per pixel (none without layers).
pub fn layers_len(unit: &WorkUnit, frame: &FilmFrame) -> usize {
    let planes = if unit.mask.is_some() {
        frame.source_planes()
    } else {
        1
    };
    frame.region(unit).pixel_count() * planes * frame.layers.len() * BYTES_PER_LAYER_SUM
}

/// Reads the layer sums of `buffer`'s unit back from their wire form into it, checking what an
/// honest render gives: [`layers_len`] bytes; each value finite; a weighted one (a value in
/// [-1, 1] per sample, [`SumKind::Weighted`]) no larger in magnitude than the pixel's weight sum
/// can be, not negative when the filter weighs no sample negatively (alpha, albedo and the
/// depth's count never are; a normal's may be), and zero where no sample reaches; a distance
/// sum below [`MAX_SUM`] and zero where no sample reaches; a sample count exactly the unit's
/// samples per pixel in the pixels it renders (in the plane of the pixel's block) and 0
/// elsewhere.
pub fn decode_layers(
    buffer: &mut SampleBuffer,
    frame: &FilmFrame,
    weights: &WeightBounds,
    bytes: &[u8],
) -> Result<(), WireError> {
    let unit = buffer.unit;
    let expected = layers_len(&unit, frame);
    if bytes.len() != expected {
        return Err(WireError::LayersLength {
            index: unit.index,
            got: bytes.len(),
            expected,
        });
    }
    let k = frame.layers.len();
    if k == 0 {
        buffer.layers.clear();
        return Ok(());
    }
    let region = buffer.region;
    let n = region.pixel_count();
    let limits = max_weight_sums(&unit, region, weights);
    let signed = frame.layers.offsets().normal;
    let samples = (unit.sample_end - unit.sample_start) as f32;
    buffer.layers = Vec::with_capacity(expected / BYTES_PER_LAYER_SUM);
    for (at, word) in bytes.chunks_exact(BYTES_PER_LAYER_SUM).enumerate() {
        let value = f32::from_le_bytes(word.try_into().expect("4 bytes"));
        let (pixel, sum) = (at / k, at % k);
        let limit = limits[pixel % n][0];
        let refuse = |reason| WireError::LayerValue {
            index: unit.index,
            at,
            value,
            reason,
        };
        if !value.is_finite() {
            return Err(refuse("is not finite"));
        }
        if limit == 0.0 && value != 0.0 {
            return Err(refuse(
                "lies beyond the reach of every pixel the unit renders",
            ));
        }
        match frame.layers.kind(sum) {
            SumKind::Weighted => {
                let may_be_negative =
                    weights.negative || signed.is_some_and(|o| (o..o + 3).contains(&sum));
                if value < 0.0 && !may_be_negative {
                    return Err(refuse(
                        "is negative, and the scene's filter weighs no sample negatively",
                    ));
                }
                if f64::from(value.abs()) > limit {
                    return Err(refuse(
                        "exceeds the weight sum the unit's samples can give the pixel",
                    ));
                }
            }
            SumKind::Unbounded => {
                if value.abs() >= MAX_SUM {
                    return Err(refuse("exceeds what the film holds"));
                }
            }
            SumKind::Count => {
                let plane = pixel / n;
                let (x, y) = (
                    region.x0 + (pixel % n) as u32 % region.width(),
                    region.y0 + (pixel % n) as u32 / region.width(),
                );
                let own = (unit.x0..unit.x1).contains(&x)
                    && (unit.y0..unit.y1).contains(&y)
                    && unit.renders(x, y)
                    && (unit.mask.is_none() || frame.source_plane(x, y) == plane);
                let expected = if own { samples } else { 0.0 };
                if value != expected {
                    return Err(refuse("is not the samples the unit takes in the pixel"));
                }
            }
        }
        buffer.layers.push(value);
    }
    Ok(())
}

/// The wire form of a unit's light splats: per pixel, its index as a little-endian u32, then
/// its r, g, b sums as little-endian f32.
pub fn encode_splats(splats: &LightSplats) -> Bytes {
    let mut out = BytesMut::with_capacity(splats.len() * BYTES_PER_SPLAT);
    for (&pixel, rgb) in splats.pixels.iter().zip(&splats.rgb) {
        out.put_u32_le(pixel);
        rgb.iter().for_each(|&v| out.put_f32_le(v));
    }
    out.freeze()
}

/// Reads the light splats of unit `index` back from their wire form: whole pixels, no more than
/// a unit of `frame` reports (none unless it has light splats; at most the pixels of its
/// splat planes, `FilmFrame::splat_entries`, and [`MAX_SPLAT_PIXELS`]), checked before
/// anything is allocated; then what
/// [`LightSplats::check`] asks (sorted pixels inside the film, values a unit reports).
pub fn decode_splats(
    index: u32,
    frame: &FilmFrame,
    bytes: &[u8],
) -> Result<LightSplats, WireError> {
    // The film's pixels in every plane (the image's light and each light group's).
    let entries = frame.splat_entries();
    let max = MAX_SPLAT_PIXELS.min(usize::try_from(entries).unwrap_or(usize::MAX));
    let count = bytes.len() / BYTES_PER_SPLAT;
    if !bytes.len().is_multiple_of(BYTES_PER_SPLAT) || count > max {
        return Err(WireError::SplatsLength {
            index,
            got: bytes.len(),
            max,
        });
    }
    let mut splats = LightSplats {
        pixels: Vec::with_capacity(count),
        rgb: Vec::with_capacity(count),
    };
    let word = |at: &[u8]| <[u8; 4]>::try_from(at).expect("4 bytes");
    for pixel in bytes.chunks_exact(BYTES_PER_SPLAT) {
        splats.pixels.push(u32::from_le_bytes(word(&pixel[..4])));
        splats.rgb.push(std::array::from_fn(|c| {
            f32::from_le_bytes(word(&pixel[4 + 4 * c..8 + 4 * c]))
        }));
    }
    splats
        .check(frame)
        .map_err(|misfit| WireError::Splats { index, misfit })?;
    Ok(splats)
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
/// the film can hold (under [`MAX_SUM`], so one value cannot saturate it); weight sums no larger
/// in magnitude than the unit's samples can give each pixel through the scene's filter
/// (`weights`, see [`max_weight_sums`]), and none negative when the filter weighs no sample
/// negatively; zeros for the pixels no sample of the unit reaches (beyond the border of the
/// pixels it renders). Radiance has no bound short of the film's: a bright but finite sum is
/// indistinguishable from a firefly. Negative sums are honest under filters with negative
/// lobes (mitchell, sinc).
pub fn decode_pixels(
    unit: WorkUnit,
    frame: &FilmFrame,
    weights: &WeightBounds,
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
    let mut buffer = SampleBuffer::new(unit, frame);
    let n = buffer.region.pixel_count();
    let limits = max_weight_sums(&unit, buffer.region, weights);
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
        let max_weight = limits[i][usize::from(half)];
        // No sample that reaches the pixel weighs it: its radiance sums are zero too.
        if max_weight == 0.0 && values.iter().any(|&v| v != 0.0) {
            return Err(refuse(
                values[3],
                "lies beyond the reach of every pixel the unit renders",
            ));
        }
        if values[3] < 0.0 && !weights.negative {
            return Err(refuse(
                values[3],
                "is a negative weight sum, and the scene's filter weighs no sample negatively",
            ));
        }
        if f64::from(values[3].abs()) > max_weight {
            return Err(refuse(
                values[3],
                "exceeds the weight sum the unit's samples can give the pixel",
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

/// The relative rounding of one f32 operation.
const F32_ROUNDING: f64 = 1.0 / (1u64 << 24) as f64;

/// Per pixel of `region` (row-major), the largest weight sum in magnitude that `unit`'s samples
/// can give it, of all its samples and of its odd-index ones: for each pixel the unit renders,
/// its samples times the largest weight a sample there gives this one (the product of the two
/// axes' bounds at their offsets, [`WeightBounds`]). A unit's buffer adds its n terms in f32:
/// each addition rounds up by at most a factor 1 + 2^-24, and each term's weights and their
/// product a few times more, so the sum stays under exp((n + 16) 2^-24) times that bound. Zero
/// where no sample that reaches the pixel can weigh it.
pub fn max_weight_sums(
    unit: &WorkUnit,
    region: PixelRect,
    weights: &WeightBounds,
) -> Vec<[f64; 2]> {
    let rendered = match unit.mask {
        None => vec![(unit.x0, unit.y0, unit.x1, unit.y1)],
        Some(mask) => unit
            .tile_blocks()
            .filter(|&(_, _, bit)| mask & bit != 0)
            .map(|(x, y, _)| {
                let end = |v: u32, tile_end: u32| (v + BLOCK_SIZE).min(tile_end);
                (x, y, end(x, unit.x1), end(y, unit.y1))
            })
            .collect(),
    };
    // Per pixel: the sum of the bounds of the rendered pixels that reach it, and their count.
    let mut reach = vec![(0.0, 0); region.pixel_count()];
    for (x0, y0, x1, y1) in rendered {
        let columns = axis_reach(&weights.x, region.x0..region.x1, x0..x1);
        let rows = axis_reach(&weights.y, region.y0..region.y1, y0..y1);
        for (row, &(wy, ny)) in reach.chunks_exact_mut(columns.len()).zip(&rows) {
            for (pixel, &(wx, nx)) in row.iter_mut().zip(&columns) {
                pixel.0 += wx * wy;
                pixel.1 += nx * ny;
            }
        }
    }
    let samples = [
        unit.sample_end - unit.sample_start,
        (unit.sample_end / 2).saturating_sub(unit.sample_start / 2),
    ]
    .map(f64::from);
    reach
        .into_iter()
        .map(|(bound, pixels): (f64, u64)| {
            samples.map(|s| {
                let terms = s * pixels as f64;
                s * bound * libm::exp((terms + 16.0) * F32_ROUNDING)
            })
        })
        .collect()
}

/// Along one axis, for each pixel of `pixels`: the sum of the largest weights (`max`, by
/// offset from -border to border) a sample in each pixel of `sources` gives it, and how many
/// of those lie within the border.
fn axis_reach(max: &[f32], pixels: Range<u32>, sources: Range<u32>) -> Vec<(f64, u64)> {
    let border = (max.len() / 2) as i64;
    pixels
        .map(|p| {
            let p = i64::from(p);
            let near =
                (p - border).max(sources.start.into())..(p + border + 1).min(sources.end.into());
            let bound = near
                .clone()
                .map(|q| f64::from(max[(p - q + border) as usize]))
                .sum();
            (bound, near.count() as u64)
        })
        .collect()
}

/// A worker's reply to `unit`, checked: the unit's own index, a sample buffer that
/// [`decode_pixels`] accepts, layers that [`decode_layers`] accepts, light splats that
/// [`decode_splats`] accepts, and counters an honest render of the unit gives (exactly its
/// samples, no more dropped than taken, rays within [`MAX_RAYS_PER_SAMPLE`] per sample).
pub fn result_from_wire(
    unit: WorkUnit,
    frame: &FilmFrame,
    weights: &WeightBounds,
    reply: &pb::RenderUnitReply,
) -> Result<(SampleBuffer, UnitStats), WireError> {
    if reply.index != unit.index {
        return Err(WireError::OtherUnit {
            asked: unit.index,
            got: reply.index,
        });
    }
    let mut buffer = decode_pixels(unit, frame, weights, &reply.pixels)?;
    decode_layers(&mut buffer, frame, weights, &reply.layers)?;
    buffer.splats = decode_splats(unit.index, frame, &reply.light_splats)?;
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
    use std::sync::Arc;

    use yat_tracer::assets::MemorySource;
    use yat_tracer::filter::{FilterDesc, FilterKind, PixelFilter};
    use yat_tracer::parse::parse_scene;
    use yat_tracer::render::layers::Layers;
    use yat_tracer::render::{plan_units, RenderScene};

    use prost::Message;

    use super::*;

    const MITCHELL: FilterKind = FilterKind::MITCHELL;

    fn weights_of(kind: FilterKind, xwidth: f32, ywidth: f32) -> WeightBounds {
        PixelFilter::new(&FilterDesc {
            kind,
            xwidth,
            ywidth,
        })
        .weight_bounds()
    }

    /// A box filter reaching `border` pixels: every sample weighs each pixel within it 1.
    fn box_weights([bx, by]: [u32; 2]) -> WeightBounds {
        let width = |b: u32| b as f32 + 0.5;
        weights_of(FilterKind::Box, width(bx), width(by))
    }

    fn settings() -> RenderSettings {
        RenderSettings {
            width: 100,
            height: 50,
            spp: 16,
            max_depth: 5,
            seed: 7,
            latlong: LatLongConvention::LuxRender,
            transport: Default::default(),
            aovs: Default::default(),
        }
    }

    #[test]
    fn settings_round_trip_and_reject_empty_images() {
        let s = settings();
        for transport in [
            Transport::Path,
            Transport::Bidirectional,
            Transport::DirectLighting,
        ] {
            let s = RenderSettings {
                transport,
                ..s.clone()
            };
            assert_eq!(
                RenderSettings::try_from(&pb::RenderSettings::from(&s)).unwrap(),
                s
            );
        }
        let mut wire = pb::RenderSettings::from(&s);
        wire.transport = 3;
        assert!(RenderSettings::try_from(&wire).is_err());
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
            splats: LightSplats::default(),
            layers: Vec::new(),
        };
        let bytes = encode_pixels(&buffer);
        assert_eq!(bytes.len(), 6 * BYTES_PER_PIXEL);
        let weights = box_weights(frame.border);
        let back = decode_pixels(unit, &frame, &weights, &bytes).unwrap();
        let bits = |b: &SampleBuffer| {
            b.rgb
                .iter()
                .flatten()
                .chain(&b.weight)
                .map(|v| v.to_bits())
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&back), bits(&buffer));
        assert!(decode_pixels(unit, &frame, &weights, &bytes[1..]).is_err());
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
            border: [2, 1],
            ..FilmFrame::unbordered(6, 8)
        };
        // Columns 0..6 (7 clipped to the film), rows 0..3 (-1 clipped).
        assert_eq!(pixels_len(&unit, &frame), 6 * 3 * BYTES_PER_PIXEL);
        let weights = box_weights(frame.border);
        let mut buffer = SampleBuffer::new(unit, &frame);
        // Pixel (2, 2), below the tile: 4 samples from each of the 3 x 1 tile pixels within the
        // border, each weighing 1 under this box.
        buffer.rgb[2 * 6 + 2] = [1.0, 2.0, 3.0];
        buffer.weight[2 * 6 + 2] = 12.0;
        let bytes = encode_pixels(&buffer);
        assert_eq!(
            decode_pixels(unit, &frame, &weights, &bytes).unwrap(),
            buffer
        );
        let tile_only = 3 * 2 * BYTES_PER_PIXEL;
        assert!(decode_pixels(unit, &frame, &weights, &bytes[..tile_only]).is_err());
        let unclipped = FilmFrame {
            width: 100,
            ..frame
        };
        assert!(decode_pixels(unit, &unclipped, &weights, &bytes).is_err());
        // More weight than those samples give is a lie.
        buffer.weight[2 * 6 + 2] = 12.01;
        assert!(decode_pixels(unit, &frame, &weights, &encode_pixels(&buffer)).is_err());
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
        let weights = box_weights(frame.border);
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
        assert_eq!(
            decode_pixels(unit, &frame, &weights, &bytes).unwrap(),
            buffer
        );
        let one_plane = &bytes[..pixels * BYTES_PER_PIXEL];
        assert!(decode_pixels(unit, &frame, &weights, one_plane).is_err());
        let mut heavy_half = buffer.clone();
        heavy_half.half_weight[0] = 3.0;
        assert!(
            decode_pixels(unit, &frame, &weights, &encode_pixels(&heavy_half)).is_err(),
            "3 of 2 odd samples"
        );
        let mut outside = buffer.clone();
        outside.rgb[6 * 28 + 6] = [0.1, 0.0, 0.0];
        assert!(
            decode_pixels(unit, &frame, &weights, &encode_pixels(&outside)).is_err(),
            "a masked-out pixel"
        );

        // With a 2-pixel border, active blocks splat into their neighbours (in 4 source
        // planes): pixels within 2 of block (0, 0) may hold sums in any plane, those farther
        // from every active block may not.
        let frame = FilmFrame {
            border: [2, 2],
            ..frame
        };
        let weights = box_weights(frame.border);
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
                let decoded = decode_pixels(unit, &frame, &weights, &encode_pixels(&buffer));
                assert_eq!(decoded.is_ok(), reached, "({x}, {y}) in plane {plane}");
            }
        }
    }

    /// A 4x4 tile of 8 samples per pixel at (4, 4) of a 16x16 film, with a filter reaching 2
    /// pixels: its buffer covers (2, 2) to (10, 10).
    fn bordered_unit() -> (WorkUnit, FilmFrame) {
        let unit = WorkUnit {
            index: 9,
            x0: 4,
            y0: 4,
            x1: 8,
            y1: 8,
            sample_start: 8,
            sample_end: 16,
            mask: None,
        };
        let frame = FilmFrame {
            border: [2, 2],
            ..FilmFrame::unbordered(16, 16)
        };
        (unit, frame)
    }

    /// `unit`'s buffer with `weight` (and some radiance) at `(x, y)`, checked under `weights`.
    fn weighing(
        (unit, frame): (WorkUnit, FilmFrame),
        weights: &WeightBounds,
        (x, y): (u32, u32),
        weight: f32,
    ) -> Result<SampleBuffer, WireError> {
        let mut buffer = SampleBuffer::new(unit, &frame);
        let region = buffer.region;
        let at = ((y - region.y0) * region.width() + x - region.x0) as usize;
        buffer.rgb[at] = [0.5, 0.25, 0.125];
        buffer.weight[at] = weight;
        decode_pixels(unit, &frame, weights, &encode_pixels(&buffer))
    }

    /// A negative weight sum is a lie under a filter that weighs no sample negatively, refused
    /// naming the pixel; under mitchell's or sinc's negative lobes it is honest. Zero is honest
    /// under any filter.
    #[test]
    fn negative_weights_are_refused_unless_the_filter_has_negative_lobes() {
        let (x, y) = (3, 5);
        // Pixel (3, 5) is the 14th of the region's row 3.
        let pixel = 3 * 8 + 1;
        for (kind, width, negative) in [
            (FilterKind::Box, 2.5, false),
            (FilterKind::Triangle, 2.0, false),
            (FilterKind::Gaussian { alpha: 2.0 }, 2.0, false),
            (FilterKind::BlackmanHarris, 2.0, false),
            (MITCHELL, 2.0, true),
            (
                FilterKind::Mitchell {
                    b: 0.0,
                    c: 0.5,
                    supersample: true,
                },
                2.0,
                true,
            ),
            (FilterKind::CatmullRom, 2.0, true),
            (FilterKind::Sinc { tau: 3.0 }, 2.0, true),
        ] {
            let weights = weights_of(kind, width, width);
            assert_eq!(weights.negative, negative, "{kind:?}");
            for zero in [0.0, -0.0] {
                assert!(weighing(bordered_unit(), &weights, (x, y), zero).is_ok());
            }
            let decoded = weighing(bordered_unit(), &weights, (x, y), -0.25);
            match decoded {
                Ok(_) => assert!(negative, "{kind:?}: a negative weight accepted"),
                Err(WireError::PixelValue {
                    index: 9,
                    pixel: p,
                    value,
                    reason,
                }) => {
                    assert!(!negative, "{kind:?}: refused: {reason}");
                    assert_eq!((p, value), (pixel, -0.25), "{kind:?}");
                    assert!(reason.contains("negative"), "{reason}");
                }
                Err(e) => panic!("{kind:?}: {e}"),
            }
        }
    }

    /// A weight sum above what the unit's samples give the pixel through the filter is refused,
    /// where the bound over every pixel within the border weighing 1 would let it pass.
    #[test]
    fn weight_sums_beyond_what_the_samples_can_give_are_refused() {
        let gaussian = weights_of(FilterKind::Gaussian { alpha: 2.0 }, 2.0, 2.0);
        // The region's corner (2, 2) gets only the tile's corner (4, 4), two pixels away on
        // each axis, where a sample weighs at most 0.0114^2 (the gaussian at 1.49 pixels): 8
        // samples give at most 1.04e-3.
        let corner = (2, 2);
        assert!(weighing(bordered_unit(), &gaussian, corner, 1e-3).is_ok());
        let refused = weighing(bordered_unit(), &gaussian, corner, 1.1e-3).unwrap_err();
        assert!(
            refused.to_string().contains("exceeds the weight sum"),
            "{refused}"
        );
        // The tile's (6, 6) gets 4 x 4 tile pixels, at most (1 + 2 x 0.616 + 0.0114)^2 = 5.03
        // per sample: 40.3 in all.
        let inside = (6, 6);
        assert!(weighing(bordered_unit(), &gaussian, inside, 40.0).is_ok());
        assert!(weighing(bordered_unit(), &gaussian, inside, 41.0).is_err());
        assert!(weighing(bordered_unit(), &gaussian, inside, -41.0).is_err());
        // Under a box every sample within the border weighs 1: 8 x 16 at (6, 6).
        let box_filter = box_weights([2, 2]);
        assert!(weighing(bordered_unit(), &box_filter, inside, 128.0).is_ok());
        // A sum in f32 may round past the exact bound: one step above it is honest.
        let rounded_up = 128.0f32.next_up();
        assert!(weighing(bordered_unit(), &box_filter, inside, rounded_up).is_ok());
        assert!(weighing(bordered_unit(), &box_filter, inside, 128.01).is_err());
        // Under mitchell the bound holds negative sums too.
        let mitchell = weights_of(MITCHELL, 2.0, 2.0);
        assert!(weighing(bordered_unit(), &mitchell, corner, -1e-3).is_ok());
        assert!(weighing(bordered_unit(), &mitchell, corner, -0.5).is_err());
    }

    /// A small scene with `filter` as its `PixelFilter` statement: a lit sphere on a floor.
    fn filtered_scene(filter: &str, width: u32, height: u32) -> (RenderScene, RenderSettings) {
        let text = format!(
            "Film \"fleximage\" \"integer xresolution\" [{width}] \"integer yresolution\" [{height}]\n\
             PixelFilter {filter}\n\
             LookAt 0 -3 1  0 0 0.3  0 0 1\n\
             Camera \"perspective\" \"float fov\" [50]\n\
             WorldBegin\n\
             AttributeBegin\n\
             AreaLightSource \"area\" \"color L\" [4 4 4]\n\
             Translate 0.6 0.2 1.6\n\
             Shape \"sphere\" \"float radius\" 0.3\n\
             AttributeEnd\n\
             Material \"matte\" \"color Kd\" [0.6 0.6 0.6]\n\
             Shape \"sphere\" \"float radius\" 0.5\n\
             Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \
             \"point P\" [-4 -4 -0.5  4 -4 -0.5  4 4 -0.5  -4 4 -0.5]\n\
             WorldEnd\n"
        );
        let mut source = MemorySource::new();
        source.insert("scene.lxs", Arc::from(text.as_bytes()));
        let desc = parse_scene("scene.lxs", &source).unwrap();
        let settings = RenderSettings {
            width,
            height,
            spp: 24,
            max_depth: 4,
            seed: 3,
            latlong: LatLongConvention::LuxRender,
            transport: Default::default(),
            aovs: Default::default(),
        };
        let scene = RenderScene::build(&desc, &source, &settings).unwrap();
        (scene, settings)
    }

    /// Honest buffers pass under every filter kind, widths from a box's own pixel to the
    /// widest, the plan's units and a tile inside the film, uniform and masked (an odd sample
    /// range); under a box of
    /// half-width 0.5 every sample weighs 1, so honest sums meet the bound.
    #[test]
    fn honest_buffers_pass_under_every_filter() {
        let filters = [
            "\"box\"",
            "\"box\" \"float xwidth\" [1.5] \"float ywidth\" [0.7]",
            "\"triangle\"",
            "\"gaussian\" \"float alpha\" [0.5] \"float xwidth\" [3]",
            "\"mitchell\"",
            "\"mitchell\" \"float B\" [1] \"float C\" [0]",
            "\"catmullrom\"",
            "\"blackmanharris\"",
            "\"sinc\"",
            "\"triangle\" \"float xwidth\" [8] \"float ywidth\" [8]",
        ];
        // A tile inside the film, uniform and masked (7 x 8 blocks: no bit of the eighth column).
        let masks = [
            None,
            Some(u64::MAX),
            Some(0x0000_0018_2400_0081),
            Some(1 << 9),
        ];
        for filter in filters {
            let (scene, settings) = filtered_scene(filter, 40, 36);
            let frame = scene.frame();
            let weights = PixelFilter::new(&scene.desc().filter).weight_bounds();
            let inner = masks.iter().map(|&mask| WorkUnit {
                index: 0,
                x0: 6,
                y0: 3,
                x1: 34,
                y1: 33,
                sample_start: 3,
                sample_end: 14,
                mask: mask.map(|m| m & 0x7f7f_7f7f_7f7f_7f7f),
            });
            let mut tightest = 0.0f64;
            for unit in plan_units(&settings).into_iter().chain(inner) {
                let (buffer, _) = scene.render_unit(&unit);
                let decoded = decode_pixels(unit, &frame, &weights, &encode_pixels(&buffer));
                assert_eq!(decoded.unwrap(), buffer, "{filter}: {unit:?}");
                let limits = max_weight_sums(&unit, buffer.region, &weights);
                let n = buffer.region.pixel_count();
                let sums = buffer.weight.iter().chain(&buffer.half_weight);
                for (i, &w) in sums.enumerate() {
                    let limit = limits[i % n][usize::from(i >= buffer.weight.len())];
                    if limit > 0.0 {
                        tightest = tightest.max(f64::from(w.abs()) / limit);
                    }
                }
            }
            println!(
                "{filter} (negative weights: {}): honest weight sums reach {tightest:.4} of \
                 the bound",
                weights.negative
            );
            if filter == "\"box\"" {
                assert!(tightest > 0.9999, "{tightest}");
            }
        }
    }

    /// `reply` to `unit` of a 2x1 film, checked under a mitchell filter of half-width 0.5 (it
    /// reaches no neighbour, and weighs some samples negatively).
    fn check_2x1(
        unit: WorkUnit,
        reply: &pb::RenderUnitReply,
    ) -> Result<(SampleBuffer, UnitStats), WireError> {
        let weights = weights_of(MITCHELL, 0.5, 0.5);
        result_from_wire(unit, &FilmFrame::unbordered(2, 1), &weights, reply)
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
            splats: LightSplats::default(),
            layers: Vec::new(),
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
            light_splats: Bytes::new(),
            layers: Bytes::new(),
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
            let (buffer, stats) = check_2x1(unit, &reply).unwrap();
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
            let error = check_2x1(unit, &reply).unwrap_err();
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
            check_2x1(unit, &other),
            Err(WireError::OtherUnit { asked: 5, got: 6 })
        ));
        let short = pb::RenderUnitReply {
            pixels: reply.pixels.slice(..16),
            ..reply.clone()
        };
        assert!(matches!(
            check_2x1(unit, &short),
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
                matches!(check_2x1(unit, &lying), Err(WireError::Stats { .. })),
                "{samples} {rays} {dropped}"
            );
        }
        let without_stats = pb::RenderUnitReply {
            stats: None,
            ..reply
        };
        assert!(check_2x1(unit, &without_stats).is_err());
    }

    /// A 4x4 tile at (4, 4) of a 32x16 film with light splats, and `k` splat pixels spread
    /// over the film.
    fn splat_unit(k: u32) -> (WorkUnit, FilmFrame, SampleBuffer) {
        let frame = FilmFrame {
            light_splats: true,
            ..FilmFrame::unbordered(32, 16)
        };
        let unit = WorkUnit {
            index: 2,
            x0: 4,
            y0: 4,
            x1: 8,
            y1: 8,
            sample_start: 0,
            sample_end: 4,
            mask: None,
        };
        let mut buffer = SampleBuffer::new(unit, &frame);
        buffer.weight[5] = 4.0;
        buffer.rgb[5] = [1.0, 2.0, 3.0];
        buffer.splats = LightSplats {
            pixels: (0..k).map(|i| i * 512 / k.max(1)).collect(),
            rgb: (0..k)
                .map(|i| [i as f32 * 0.3, -0.0, f32::MIN_POSITIVE * i as f32])
                .collect(),
        };
        (unit, frame, buffer)
    }

    fn reply_of(buffer: &SampleBuffer) -> pb::RenderUnitReply {
        pb::RenderUnitReply {
            index: buffer.unit.index,
            pixels: encode_pixels(buffer),
            stats: Some(pb::UnitStats {
                samples: buffer.unit.sample_count(),
                rays: 100,
                dropped: 0,
            }),
            render_seconds: 0.5,
            light_splats: encode_splats(&buffer.splats),
            layers: encode_layers(buffer),
        }
    }

    /// The alpha unit of [`bordered_unit`]: alpha sums beside its weights.
    fn alpha_unit() -> (WorkUnit, FilmFrame, SampleBuffer) {
        let (unit, plain) = bordered_unit();
        let frame = FilmFrame {
            layers: Layers {
                alpha: true,
                ..Layers::NONE
            },
            ..plain
        };
        let mut buffer = SampleBuffer::new(unit, &frame);
        for (i, (w, a)) in buffer.weight.iter_mut().zip(&mut buffer.layers).enumerate() {
            *w = 4.0;
            *a = [0.0, 4.0, 1.25, f32::MIN_POSITIVE][i % 4];
        }
        (unit, frame, buffer)
    }

    /// Alpha reads back bit-exactly, 4 bytes a pixel of the buffer's region more on the wire;
    /// a render without layers sends none (its reply as it always was).
    #[test]
    fn alpha_round_trips_bit_exactly_at_4_bytes_a_pixel() {
        let (unit, frame, buffer) = alpha_unit();
        let weights = box_weights(frame.border);
        let reply = reply_of(&buffer);
        assert_eq!(reply.layers.len(), 64 * BYTES_PER_LAYER_SUM);
        assert_eq!(layers_len(&unit, &frame), 64 * 4);
        let wire = pb::RenderUnitReply::decode(reply.encode_to_vec().as_slice()).unwrap();
        let (back, _) = result_from_wire(unit, &frame, &weights, &wire).unwrap();
        assert_eq!(back, buffer);
        let bits = |b: &SampleBuffer| b.layers.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back), bits(&buffer));
        let without = pb::RenderUnitReply {
            layers: Bytes::new(),
            ..reply.clone()
        };
        // The field's tag and its length take the bytes beyond 4 a pixel.
        let added = reply.encoded_len() - without.encoded_len();
        assert!((256..256 + 4).contains(&added), "{added}");
        let (_, plain) = bordered_unit();
        assert_eq!(layers_len(&unit, &plain), 0);
        let plain_reply = reply_of(&SampleBuffer::new(unit, &plain));
        assert!(plain_reply.layers.is_empty());
    }

    /// Hostile alpha is refused naming the unit: bytes for another layout (too few, too many,
    /// any on a film that keeps none), non-finite values, more than the pixel's weight can
    /// give, negative under a filter without negative lobes, any beyond the unit's reach.
    #[test]
    fn hostile_alpha_is_refused() {
        let (unit, frame, buffer) = alpha_unit();
        let (_, plain) = bordered_unit();
        let weights = box_weights(frame.border);
        let check = |frame: &FilmFrame, layers: Bytes| {
            let reply = pb::RenderUnitReply {
                layers,
                ..reply_of(&buffer)
            };
            result_from_wire(unit, frame, &weights, &reply).map(|_| ())
        };
        let honest = encode_layers(&buffer);
        assert!(check(&frame, honest.clone()).is_ok());
        for layers in [honest.slice(..honest.len() - 4), Bytes::new()] {
            assert!(matches!(
                check(&frame, layers),
                Err(WireError::LayersLength {
                    index: 9,
                    expected: 256,
                    ..
                })
            ));
        }
        let longer = [honest.as_ref(), &[0; 4]].concat();
        assert!(check(&frame, longer.into()).is_err());
        assert!(matches!(
            check(&plain, honest.clone()),
            Err(WireError::LayersLength { expected: 0, .. })
        ));
        // The region's pixel (2, 2) is reached by the tile's (4, 4) through a 2-pixel border;
        // a box filter of that border weighs each sample at most 1 there: 8 samples, 8.
        for (at, value, reason) in [
            (0, f32::NAN, "not finite"),
            (0, f32::INFINITY, "not finite"),
            (0, 9.0, "exceeds"),
            (0, -0.5, "negative"),
        ] {
            let mut hostile = buffer.clone();
            hostile.layers[at] = value;
            let error = check(&frame, encode_layers(&hostile))
                .unwrap_err()
                .to_string();
            assert!(
                error.contains(reason) && error.contains("unit 9"),
                "{error}"
            );
        }
    }

    /// The AOVs travel in the settings as bits; an unknown bit is refused, and settings
    /// without AOVs encode as they always did (so a render's identity stays).
    #[test]
    fn aovs_travel_in_the_settings() {
        let with = RenderSettings {
            aovs: Aovs::from_names("normal,samples").unwrap(),
            ..settings()
        };
        let wire = pb::RenderSettings::from(&with);
        assert_eq!(wire.aovs, 0b1010);
        assert_eq!(RenderSettings::try_from(&wire).unwrap(), with);
        let unknown = pb::RenderSettings { aovs: 16, ..wire };
        assert!(RenderSettings::try_from(&unknown).is_err());
        let plain = pb::RenderSettings::from(&settings());
        let old = pb::RenderSettings { aovs: 0, ..plain };
        assert_eq!(plain.encode_to_vec(), old.encode_to_vec());
    }

    /// Every AOV's sums are checked for what they hold: a normal may be negative where alpha
    /// and albedo may not, a distance sum may be large but under the film's range, and the
    /// sample count must be exactly the unit's samples in its own pixels and 0 in the border.
    #[test]
    fn aov_sums_are_checked_by_kind() {
        let (unit, plain) = bordered_unit();
        let frame = FilmFrame {
            layers: Layers {
                alpha: true,
                aovs: Aovs::from_bits(15).unwrap(),
                light_groups: 0,
            },
            ..plain
        };
        let k = frame.layers.len();
        assert_eq!(k, 10);
        let mut buffer = SampleBuffer::new(unit, &frame);
        let region = buffer.region;
        for (i, w) in buffer.weight.iter_mut().enumerate() {
            *w = 4.0;
            let (x, y) = (region.x0 + i as u32 % 8, region.y0 + i as u32 / 8);
            let own = (4..8).contains(&x) && (4..8).contains(&y);
            let sums = [4.0, 1.0, 2.0, 3.0, -4.0, 0.0, 4.0, 1e6, 4.0, 0.0];
            buffer.layers[i * k..(i + 1) * k].copy_from_slice(&sums);
            buffer.layers[i * k + 9] = if own { 8.0 } else { 0.0 };
        }
        let weights = box_weights(frame.border);
        let check = |b: &SampleBuffer| {
            let reply = reply_of(b);
            result_from_wire(unit, &frame, &weights, &reply).map(|_| ())
        };
        check(&buffer).unwrap();
        // Pixel (4, 4) is the region's 18th (row 2, column 2).
        let own = 2 * 8 + 2;
        for (sum, value, reason) in [
            (9, 7.0, "not the samples"),
            (2, -1.0, "negative"),
            (7, 1e12, "exceeds what the film holds"),
            (5, 100.0, "exceeds the weight sum"),
        ] {
            let mut hostile = buffer.clone();
            hostile.layers[own * k + sum] = value;
            let error = check(&hostile).unwrap_err().to_string();
            assert!(error.contains(reason), "sum {sum}: {error}");
        }
        let mut border = buffer.clone();
        border.layers[9] = 8.0;
        assert!(check(&border)
            .unwrap_err()
            .to_string()
            .contains("not the samples"));
    }

    /// A reply with light splats reads back bit-exactly, splats included.
    #[test]
    fn light_splats_round_trip_bit_exactly() {
        let (unit, frame, buffer) = splat_unit(37);
        let weights = box_weights(frame.border);
        let reply = pb::RenderUnitReply::decode(reply_of(&buffer).encode_to_vec().as_slice());
        let (back, _) = result_from_wire(unit, &frame, &weights, &reply.unwrap()).unwrap();
        assert_eq!(back, buffer);
        let bits = |b: &SampleBuffer| -> Vec<u32> {
            b.splats.rgb.iter().flatten().map(|v| v.to_bits()).collect()
        };
        assert_eq!(bits(&back), bits(&buffer));
        assert_eq!(back.splats.len(), 37);
    }

    /// What a splat pixel costs on the wire: its 16 bytes, and a few bytes of framing per
    /// reply.
    #[test]
    fn a_splat_pixel_costs_16_bytes_on_the_wire() {
        let size = |k: u32| reply_of(&splat_unit(k).2).encoded_len();
        let base = size(0);
        for k in [1, 10, 100, 512] {
            let per_pixel = (size(k) - base) as f64 / f64::from(k);
            println!(
                "{k} splat pixels: {} bytes more, {per_pixel:.3} per pixel",
                size(k) - base
            );
            // The field's tag and length: 2 to 4 bytes per reply.
            assert!(
                per_pixel >= 16.0 && per_pixel <= 16.0 + 4.0 / f64::from(k),
                "{per_pixel}"
            );
        }
        assert_eq!(BYTES_PER_SPLAT, 16);
        assert_eq!(MAX_SPLAT_PIXELS * BYTES_PER_SPLAT, 4 << 20);
    }

    /// Hostile splats are refused before a film sees them: a partial pixel, more pixels than
    /// the film has, splats on a film that keeps none, unsorted or repeated pixels, a pixel
    /// outside the film, non-finite or huge values.
    #[test]
    fn hostile_light_splats_are_refused() {
        let (unit, frame, buffer) = splat_unit(3);
        let weights = box_weights(frame.border);
        let check = |frame: &FilmFrame, light_splats: Bytes| {
            let reply = pb::RenderUnitReply {
                light_splats,
                ..reply_of(&buffer)
            };
            result_from_wire(unit, frame, &weights, &reply).map(|_| ())
        };
        assert!(check(&frame, encode_splats(&buffer.splats)).is_ok());
        let encoded = encode_splats(&buffer.splats);
        let partial = encoded.slice(..encoded.len() - 1);
        assert!(matches!(
            check(&frame, partial),
            Err(WireError::SplatsLength {
                index: 2,
                max: 512,
                ..
            })
        ));
        let too_many = encode_splats(&LightSplats {
            pixels: (0..513).collect(),
            rgb: vec![[0.0; 3]; 513],
        });
        assert!(matches!(
            check(&frame, too_many),
            Err(WireError::SplatsLength { got: 8208, .. })
        ));
        let without = FilmFrame {
            light_splats: false,
            ..frame
        };
        assert!(matches!(
            check(&without, encode_splats(&buffer.splats)),
            Err(WireError::SplatsLength { max: 0, .. })
        ));
        assert!(check(&without, Bytes::new()).is_ok());
        for (pixels, rgb, what) in [
            (vec![9, 3], [1.0; 3], "not strictly increasing"),
            (vec![3, 3], [1.0; 3], "not strictly increasing"),
            (vec![511, 512], [1.0; 3], "outside the film"),
            (vec![0, 1], [0.0, f32::NAN, 0.0], "not finite"),
            (vec![0, 1], [f32::INFINITY, 0.0, 0.0], "not finite"),
            (vec![0, 1], [0.0, 0.0, -1e12], "not finite or exceeds"),
        ] {
            let splats = LightSplats {
                pixels,
                rgb: vec![rgb; 2],
            };
            let error = check(&frame, encode_splats(&splats)).unwrap_err();
            assert!(
                matches!(error, WireError::Splats { index: 2, .. }),
                "{error}"
            );
            assert!(error.to_string().contains(what), "{error}");
        }
    }
}
