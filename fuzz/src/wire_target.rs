//! The wire target: what arrives over the network, as a session of frames (each a message
//! kind and its bytes), decoded with prost into the `yat_proto::pb` message of that kind and
//! handed to the code each end runs on it:
//! - a worker: the protocol version check, blob names ([`is_sha256_hex`]) and the streamed
//!   hash of blob chunks, [`RenderSettings::try_from`] and the scene id of a load request,
//!   [`unit_from_wire`] against the session's settings, the token check ([`RequireToken`])
//!   on hostile `authorization` metadata;
//! - a coordinator: [`decode_pixels`], [`decode_layers`] and [`decode_splats`] of a reply for
//!   the session's unit (a film with light splats when the settings' seed is odd, with alpha
//!   when its second bit is set), the buffer merged
//!   into a [`Film`] and tone mapped for display, [`UnitStats`] from the reply, a drain
//!   signal ([`is_draining`]) in a status read from hostile trailers.
//!
//! The worker's node and blob upload logic are private to `yat-worker` (reachable only over a
//! socket through `serve`), so they are not called here; their inputs' checks are.
//!
//! Frames are mutated as bytes ([`Mutator`]) and as protobuf: a field of the raw wire format
//! (varint, fixed, length-delimited, nested) set to an extreme value, its length forged, or
//! its content mutated; frames are also dropped, duplicated, swapped and re-labelled.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::LazyLock;

use fastrand::Rng;
use prost::Message;
use tonic::metadata::{MetadataMap, MetadataValue};
use tonic::service::Interceptor;
use tonic::{Request, Status};
use yat_proto::auth::RequireToken;
use yat_proto::convert::{
    decode_layers, decode_pixels, decode_splats, encode_splats, unit_from_wire, BYTES_PER_PIXEL,
};
use yat_proto::drain::{is_draining, DRAINING_KEY};
use yat_proto::hash::{is_sha256_hex, sha256_hex, Sha256Stream};
use yat_proto::{pb, PROTOCOL_VERSION};
use yat_tracer::desc::{FilmDesc, ToneMap};
use yat_tracer::film::{Film, LightSplats};
use yat_tracer::filter::{FilterDesc, FilterKind, PixelFilter, WeightBounds};
use yat_tracer::render::layers::Layers;
use yat_tracer::render::unit::FilmFrame;
use yat_tracer::render::{RenderSettings, UnitStats, WorkUnit};

use crate::campaign::{Outcome, Target};
use crate::mutate::Mutator;

/// Largest frame: a 64x64 tile's pixels and some.
const MAX_FRAME_BYTES: usize = 80 << 10;
/// Frames in a session, at most.
const MAX_FRAMES: usize = 12;
/// Films larger than this are not allocated by the fuzzer (a coordinator's film is sized by
/// its own settings, not by a peer).
const MAX_FILM_PIXELS: u64 = 1 << 16;
/// The token the simulated worker requires.
const TOKEN: &str = "s3cret-token";

/// What a frame carries: one message of `render.proto`, or gRPC metadata.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    HandshakeRequest,
    HandshakeReply,
    HasBlobsRequest,
    HasBlobsReply,
    BlobChunk,
    PutBlobReply,
    LoadSceneRequest,
    LoadSceneReply,
    RenderUnitRequest,
    RenderUnitReply,
    StatsRequest,
    StatsReply,
    /// The value of a request's `authorization` entry.
    Authorization,
    /// A status's trailers: `grpc-status`, `grpc-message` and `yat-draining`, as three
    /// NUL-separated parts.
    StatusTrailers,
}

const KINDS: [Kind; 14] = [
    Kind::HandshakeRequest,
    Kind::HandshakeReply,
    Kind::HasBlobsRequest,
    Kind::HasBlobsReply,
    Kind::BlobChunk,
    Kind::PutBlobReply,
    Kind::LoadSceneRequest,
    Kind::LoadSceneReply,
    Kind::RenderUnitRequest,
    Kind::RenderUnitReply,
    Kind::StatsRequest,
    Kind::StatsReply,
    Kind::Authorization,
    Kind::StatusTrailers,
];

#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub kind: Kind,
    pub bytes: Vec<u8>,
}

/// A session: frames handled in order, each with the state the ones before left.
#[derive(Clone, Debug, PartialEq)]
pub struct Session {
    pub frames: Vec<Frame>,
}

impl Session {
    /// One byte of kind, four of length (little-endian), the bytes; per frame.
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::new();
        for f in &self.frames {
            let kind = KINDS.iter().position(|k| *k == f.kind).unwrap_or_default();
            out.push(kind as u8);
            out.extend_from_slice(&(f.bytes.len() as u32).to_le_bytes());
            out.extend_from_slice(&f.bytes);
        }
        out
    }

    pub fn decode(mut data: &[u8]) -> Option<Self> {
        let mut frames = Vec::new();
        while let [kind, rest @ ..] = data {
            let kind = *KINDS.get(usize::from(*kind))?;
            let len = u32::from_le_bytes(rest.get(..4)?.try_into().ok()?) as usize;
            let bytes = rest.get(4..4 + len)?.to_vec();
            frames.push(Frame { kind, bytes });
            data = &rest[4 + len..];
        }
        Some(Self { frames })
    }
}

pub struct WireTarget {
    /// Frames handled, per kind and path number (see [`handle`]).
    paths: RefCell<BTreeMap<u64, u64>>,
    corpus: Vec<Session>,
    mutator: Mutator,
}

impl Default for WireTarget {
    fn default() -> Self {
        Self::new()
    }
}

impl WireTarget {
    pub fn new() -> Self {
        Self {
            paths: RefCell::default(),
            corpus: seed_sessions(),
            mutator: Mutator::new(
                MAX_FRAME_BYTES,
                &["Bearer ", "Bearer s3cret-token", "14", "yat-draining"],
            ),
        }
    }
}

impl Target for WireTarget {
    type Input = Session;

    fn name(&self) -> &'static str {
        "wire"
    }

    fn generate(&mut self, rng: &mut Rng) -> Session {
        let mut session = self.corpus[rng.usize(0..self.corpus.len())].clone();
        for _ in 0..rng.usize(1..=3) {
            let n = session.frames.len();
            match rng.u8(0..20) {
                0 if n > 1 => {
                    session.frames.remove(rng.usize(0..n));
                }
                1 if n < MAX_FRAMES => {
                    let f = session.frames[rng.usize(0..n)].clone();
                    session.frames.insert(rng.usize(0..=n), f);
                }
                2 if n > 1 => session.frames.swap(rng.usize(0..n), rng.usize(0..n)),
                3 => session.frames[rng.usize(0..n)].kind = KINDS[rng.usize(0..KINDS.len())],
                4 => {
                    let len = rng.usize(0..64);
                    session.frames[rng.usize(0..n)].bytes =
                        std::iter::repeat_with(|| rng.u8(..)).take(len).collect();
                }
                5..=11 => {
                    let frame = &mut session.frames[rng.usize(0..n)];
                    mutate_protobuf(rng, &mut frame.bytes, 0);
                    frame.bytes.truncate(MAX_FRAME_BYTES);
                }
                _ => {
                    let other = &self.corpus[rng.usize(0..self.corpus.len())];
                    let other = &other.frames[rng.usize(0..other.frames.len())].bytes;
                    let frame = &mut session.frames[rng.usize(0..n)];
                    self.mutator.mutate(rng, &mut frame.bytes, other);
                }
            }
        }
        session
    }

    fn execute(&self, session: &Session) -> Outcome {
        let mut state = State::default();
        let features: Vec<u64> = session
            .frames
            .iter()
            .map(|f| handle(&mut state, f))
            .collect();
        let mut paths = self.paths.borrow_mut();
        for f in &features {
            *paths.entry(*f).or_default() += 1;
        }
        Outcome {
            features,
            parsed: true,
        }
    }

    fn learn(&mut self, _session: Session, _outcome: Outcome) {
        // Every handler is small and its branches few: the seeds and mutations reach them
        // all, so no input is kept (the corpus stays the seeds, and runs stay reproducible).
    }

    fn shrink(&self, session: &Session) -> Vec<Session> {
        let mut out = Vec::new();
        for i in 0..session.frames.len() {
            let mut s = session.clone();
            s.frames.remove(i);
            out.push(s);
        }
        for i in 0..session.frames.len() {
            let len = session.frames[i].bytes.len();
            let mut size = len.div_ceil(2);
            while size >= 1 {
                let mut start = 0;
                while start < len {
                    let mut s = session.clone();
                    s.frames[i].bytes.drain(start..(start + size).min(len));
                    out.push(s);
                    start += size;
                }
                size /= 2;
            }
        }
        out
    }

    fn save(&self, session: &Session, path: &Path) -> std::io::Result<PathBuf> {
        let path = path.with_extension("session");
        std::fs::write(&path, session.encode())?;
        Ok(path)
    }

    fn progress(&self) -> String {
        let paths = self.paths.borrow();
        let frames: u64 = paths.values().sum();
        let decoded: u64 = paths
            .iter()
            .filter(|(p, _)| *p % 16 > 0)
            .map(|(_, n)| n)
            .sum();
        let merged = paths
            .iter()
            .filter(|(p, _)| {
                **p >= Kind::RenderUnitReply as u64 * 16 + 7
                    && **p < Kind::RenderUnitReply as u64 * 16 + 16
            })
            .map(|(_, n)| n)
            .sum::<u64>();
        format!(
            "{frames} frames, {decoded} decoded, {merged} replies merged into a film; {} distinct paths",
            paths.len()
        )
    }
}

/// What a session's earlier frames left: the settings of the scene loaded, the unit asked
/// for, the film results merge into.
#[derive(Default)]
struct State {
    settings: Option<RenderSettings>,
    unit: Option<WorkUnit>,
    film: Option<Film>,
}

/// Handles one frame; returns a number standing for the path taken.
fn handle(state: &mut State, frame: &Frame) -> u64 {
    let bytes = &frame.bytes[..];
    let base = frame.kind as u64 * 16;
    let path = match frame.kind {
        Kind::HandshakeRequest => decoded(pb::HandshakeRequest::decode(bytes), |r| {
            u64::from(r.protocol_version == PROTOCOL_VERSION)
        }),
        Kind::HandshakeReply => decoded(pb::HandshakeReply::decode(bytes), |r| {
            u64::from(r.protocol_version == PROTOCOL_VERSION)
        }),
        Kind::HasBlobsRequest => decoded(pb::HasBlobsRequest::decode(bytes), |r| {
            r.sha256.iter().filter(|h| is_sha256_hex(h)).count().min(3) as u64
        }),
        Kind::HasBlobsReply => decoded(pb::HasBlobsReply::decode(bytes), |r| {
            u64::from(r.missing.iter().all(|h| is_sha256_hex(h)))
        }),
        Kind::BlobChunk => decoded(pb::BlobChunk::decode(bytes), |chunk| {
            let mut stream = Sha256Stream::default();
            stream.update(&chunk.data);
            let matches = stream.finish_hex() == chunk.sha256;
            u64::from(is_sha256_hex(&chunk.sha256)) + 2 * u64::from(matches)
        }),
        Kind::PutBlobReply => decoded(pb::PutBlobReply::decode(bytes), |_| 0),
        Kind::LoadSceneRequest => decoded(pb::LoadSceneRequest::decode(bytes), |r| {
            let _scene_id = sha256_hex(&r.encode_to_vec());
            let hashes_ok = r
                .main
                .iter()
                .chain(&r.assets)
                .all(|f| is_sha256_hex(&f.sha256));
            let Some(wire) = &r.settings else { return 1 };
            match RenderSettings::try_from(wire) {
                Ok(settings) => {
                    state.film = film_for(&settings);
                    state.settings = Some(settings);
                    2 + u64::from(hashes_ok)
                }
                Err(_) => 4,
            }
        }),
        Kind::LoadSceneReply => decoded(pb::LoadSceneReply::decode(bytes), |r| {
            u64::from(is_sha256_hex(&r.scene_id))
        }),
        Kind::RenderUnitRequest => decoded(pb::RenderUnitRequest::decode(bytes), |r| {
            let (Some(unit), Some(settings)) = (&r.unit, &state.settings) else {
                return 1;
            };
            match unit_from_wire(unit, settings) {
                Ok(unit) => {
                    state.unit = Some(unit);
                    2
                }
                Err(_) => 3,
            }
        }),
        Kind::RenderUnitReply => decoded(pb::RenderUnitReply::decode(bytes), |reply| {
            let (Some(unit), Some(settings)) = (state.unit, &state.settings) else {
                return 1;
            };
            if reply.index != unit.index {
                return 2;
            }
            let _stats = UnitStats::from(reply.stats.unwrap_or_default());
            let frame = frame_for(settings);
            let Ok(mut buffer) = decode_pixels(unit, &frame, &WEIGHTS, &reply.pixels) else {
                return 3;
            };
            if decode_layers(&mut buffer, &frame, &WEIGHTS, &reply.layers).is_err() {
                return 4;
            }
            let Ok(splats) = decode_splats(unit.index, &frame, &reply.light_splats) else {
                return 5;
            };
            buffer.splats = splats;
            let Some(film) = &mut state.film else {
                return 6;
            };
            if film.add(&buffer).is_err() {
                return 7;
            }
            let tonemap = match reply.pixels.len() / BYTES_PER_PIXEL % 4 {
                0 => ToneMap::AutoLinear,
                1 => ToneMap::Linear {
                    sensitivity: 50.0,
                    exposure: 1.0,
                    fstop: 2.8,
                    gamma: 1.0,
                },
                2 => ToneMap::Reinhard {
                    prescale: 1.0,
                    postscale: 1.0,
                    burn: 6.0,
                },
                _ => ToneMap::Contrast { ywa: 1.0 },
            };
            let display = film.to_display(&FilmDesc {
                xresolution: film.width(),
                yresolution: film.height(),
                gamma: 2.2,
                tonemap,
                filename: "fuzz".into(),
                haltspp: None,
                halttime: None,
                haltthreshold: None,
                convergence_step: yat_tracer::film::DEFAULT_CONVERGENCE_STEP,
                outputs: Default::default(),
                light_groups: Default::default(),
                outlier_k: 0,
            });
            8 + u64::from(display.pixels().any(|p| p.0 != [0, 0, 0]))
        }),
        Kind::StatsRequest => decoded(pb::StatsRequest::decode(bytes), |_| 0),
        Kind::StatsReply => decoded(pb::StatsReply::decode(bytes), |r| {
            u64::from(r.uptime_seconds.is_finite())
        }),
        Kind::Authorization => match MetadataValue::try_from(bytes) {
            Ok(value) => {
                let mut request = Request::new(());
                request.metadata_mut().insert("authorization", value);
                let accepted = RequireToken::new(Some(TOKEN)).call(request).is_ok();
                1 + u64::from(accepted)
            }
            Err(_) => 0,
        },
        Kind::StatusTrailers => {
            let mut parts = bytes.splitn(3, |&b| b == 0);
            let mut trailers = MetadataMap::new();
            let mut inserted = 0;
            for key in ["grpc-status", "grpc-message", DRAINING_KEY] {
                if let Some(Ok(value)) = parts.next().map(MetadataValue::try_from) {
                    trailers.insert(key, value);
                    inserted += 1;
                }
            }
            match Status::from_header_map(&trailers.into_headers()) {
                Some(status) => 4 + u64::from(is_draining(&status)) + inserted,
                None => inserted,
            }
        }
    };
    base + path
}

/// 0 for a message that does not decode, else 1 + what `then` says of it.
fn decoded<M>(message: Result<M, prost::DecodeError>, then: impl FnOnce(M) -> u64) -> u64 {
    message.map_or(0, |m| 1 + then(m))
}

/// The filter of the scene a session's coordinator renders: the seed scenes' blackmanharris of
/// half-width 2, so replies exercise overlapping borders.
const FILTER: FilterDesc = FilterDesc {
    kind: FilterKind::BlackmanHarris,
    xwidth: 2.0,
    ywidth: 2.0,
};

/// What [`FILTER`] lets a sample weigh a pixel, tabulated once.
static WEIGHTS: LazyLock<WeightBounds> =
    LazyLock::new(|| PixelFilter::new(&FILTER).weight_bounds());

/// The frame of the settings' film; an odd seed makes it one whose units carry light splats,
/// and the seed's second bit one whose units carry alpha, so that inputs reach every kind of
/// film.
fn frame_for(settings: &RenderSettings) -> FilmFrame {
    FilmFrame {
        width: settings.width,
        height: settings.height,
        border: FILTER.border(),
        light_splats: settings.seed % 2 == 1,
        layers: Layers {
            alpha: settings.seed & 2 != 0,
            aovs: settings.aovs,
            light_groups: if settings.seed & 8 != 0 { 3 } else { 0 },
        },
    }
}

/// A film for the settings, if small enough to allocate per input.
fn film_for(settings: &RenderSettings) -> Option<Film> {
    let pixels = u64::from(settings.width) * u64::from(settings.height);
    (pixels <= MAX_FILM_PIXELS).then(|| Film::new(frame_for(settings)))
}

/// Values that break arithmetic and bounds, as varints.
const EXTREME_VARINTS: &[u64] = &[
    0,
    1,
    2,
    7,
    8,
    63,
    64,
    65,
    127,
    128,
    4096,
    65_535,
    65_536,
    65_537,
    1 << 18,
    1 << 24,
    (1 << 24) + 1,
    1 << 28,
    i32::MAX as u64,
    1 << 31,
    u32::MAX as u64 - 1,
    u32::MAX as u64,
    1 << 32,
    i64::MAX as u64,
    u64::MAX,
];

/// One field of a protobuf message in its raw wire form.
enum Field<'a> {
    Varint(u64),
    Fixed64([u8; 8]),
    Bytes(&'a [u8]),
    Fixed32([u8; 4]),
}

/// Splits raw protobuf into (field number, field); None if it is not well formed.
fn parse_fields(mut data: &[u8]) -> Option<Vec<(u64, Field<'_>)>> {
    let mut out = Vec::new();
    while !data.is_empty() {
        let key = read_varint(&mut data)?;
        let field = match key & 7 {
            0 => Field::Varint(read_varint(&mut data)?),
            1 => {
                let (v, rest) = data.split_first_chunk::<8>()?;
                data = rest;
                Field::Fixed64(*v)
            }
            2 => {
                let len = usize::try_from(read_varint(&mut data)?).ok()?;
                let bytes = data.get(..len)?;
                data = &data[len..];
                Field::Bytes(bytes)
            }
            5 => {
                let (v, rest) = data.split_first_chunk::<4>()?;
                data = rest;
                Field::Fixed32(*v)
            }
            _ => return None,
        };
        out.push((key >> 3, field));
    }
    Some(out)
}

fn read_varint(data: &mut &[u8]) -> Option<u64> {
    let mut value = 0u64;
    for shift in (0..70).step_by(7) {
        let (&b, rest) = data.split_first()?;
        *data = rest;
        value |= u64::from(b & 0x7f).checked_shl(shift).unwrap_or(0);
        if b & 0x80 == 0 {
            return Some(value);
        }
    }
    None
}

fn write_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// Rewrites one field of the message in `data` (or of a message nested in it): an extreme
/// varint, a forged length, mutated or repeated content, an extra field; falls back to random
/// bytes when `data` is not a message.
fn mutate_protobuf(rng: &mut Rng, data: &mut Vec<u8>, depth: u32) {
    let Some(fields) = parse_fields(data).filter(|f| !f.is_empty()) else {
        let at = rng.usize(0..=data.len());
        let extra = rng.usize(1..=8);
        data.splice(at..at, std::iter::repeat_with(|| rng.u8(..)).take(extra));
        return;
    };
    let target = rng.usize(0..fields.len());
    let mut out = Vec::with_capacity(data.len() + 16);
    for (i, (number, field)) in fields.iter().enumerate() {
        let wire_type = match field {
            Field::Varint(_) => 0,
            Field::Fixed64(_) => 1,
            Field::Bytes(_) => 2,
            Field::Fixed32(_) => 5,
        };
        if i != target {
            write_field(&mut out, *number, wire_type, field);
            continue;
        }
        match (field, rng.u8(0..6)) {
            (Field::Varint(_), _) => {
                write_varint(&mut out, number << 3);
                write_varint(
                    &mut out,
                    EXTREME_VARINTS[rng.usize(0..EXTREME_VARINTS.len())],
                );
            }
            (Field::Bytes(inner), 0) => {
                // A length beyond the data.
                write_varint(&mut out, (number << 3) | 2);
                write_varint(
                    &mut out,
                    inner.len() as u64 + rng.u64(1..=u64::from(u32::MAX)),
                );
                out.extend_from_slice(inner);
            }
            (Field::Bytes(inner), 1) => {
                // The same field repeated (last one wins for scalars, appended for lists).
                for _ in 0..rng.usize(2..=4) {
                    write_field(&mut out, *number, 2, &Field::Bytes(inner));
                }
            }
            (Field::Bytes(inner), 2) => {
                // Content of another length: pixel buffers, hashes, names.
                let len = *[0usize, 1, 15, 16, 17, 63, 64, 65, 1024, 16 * 64 * 64]
                    .get(rng.usize(0..10))
                    .unwrap_or(&0);
                let content: Vec<u8> = inner.iter().copied().cycle().take(len).collect();
                write_field(&mut out, *number, 2, &Field::Bytes(&content));
            }
            (Field::Bytes(inner), _) if depth < 3 => {
                let mut content = inner.to_vec();
                mutate_protobuf(rng, &mut content, depth + 1);
                write_field(&mut out, *number, 2, &Field::Bytes(&content));
            }
            _ => {
                // A fixed field made NaN, infinite or huge; or a wire type the field does not have.
                if rng.bool() {
                    write_varint(&mut out, (number << 3) | wire_type);
                    let special = [f64::NAN, f64::INFINITY, -1.0, 1e308, 0.0][rng.usize(0..5)];
                    if wire_type == 5 {
                        out.extend_from_slice(&(special as f32).to_le_bytes());
                    } else {
                        out.extend_from_slice(&special.to_le_bytes());
                    }
                } else {
                    write_varint(&mut out, number << 3);
                    write_varint(
                        &mut out,
                        EXTREME_VARINTS[rng.usize(0..EXTREME_VARINTS.len())],
                    );
                }
            }
        }
    }
    if rng.u8(0..8) == 0 {
        // An unknown field, which decoders must skip.
        write_varint(&mut out, (rng.u64(1..=40) << 3) | 2);
        write_varint(&mut out, 3);
        out.extend_from_slice(b"abc");
    }
    *data = out;
}

fn write_field(out: &mut Vec<u8>, number: u64, wire_type: u64, field: &Field<'_>) {
    write_varint(out, (number << 3) | wire_type);
    match field {
        Field::Varint(v) => write_varint(out, *v),
        Field::Fixed64(v) => out.extend_from_slice(v),
        Field::Bytes(b) => {
            write_varint(out, b.len() as u64);
            out.extend_from_slice(b);
        }
        Field::Fixed32(v) => out.extend_from_slice(v),
    }
}

/// Valid sessions of a coordinator and a worker, small and large settings, every message.
fn seed_sessions() -> Vec<Session> {
    let frame = |kind, bytes: Vec<u8>| Frame { kind, bytes };
    let mut sessions = Vec::new();
    for (seed, width, height, spp, tile) in [
        (7, 100, 50, 16, (64, 0, 100, 50)),
        (8, 8, 8, 1, (0, 0, 8, 8)),
        (9, 65_536, 4096, 1 << 24, (0, 0, 64, 64)),
    ] {
        let settings = pb::RenderSettings {
            width,
            height,
            spp,
            max_depth: 5,
            seed,
            latlong: pb::LatLongConvention::LatlongLuxrender.into(),
            transport: pb::Transport::Path.into(),
            aovs: 0,
        };
        let hash = sha256_hex(b"WorldBegin\nWorldEnd\n");
        let load = pb::LoadSceneRequest {
            main: Some(pb::SceneFile {
                path: "scene.lxs".into(),
                sha256: hash.clone(),
            }),
            assets: vec![pb::SceneFile {
                path: "meshes/a.ply".into(),
                sha256: sha256_hex(b"ply"),
            }],
            settings: Some(settings),
        };
        let unit = pb::WorkUnit {
            index: 3,
            x0: tile.0,
            y0: tile.1,
            x1: tile.2,
            y1: tile.3,
            sample_start: 0,
            sample_end: spp.min(8),
            block_mask: None,
        };
        // The tile and the border, clipped to the image.
        let [border, _] = FILTER.border();
        let side = |lo: u32, hi: u32, end: u32| {
            ((hi + border).min(end) - lo.saturating_sub(border)) as usize
        };
        let pixels = side(tile.0, tile.2, width) * side(tile.1, tile.3, height);
        let reply = pb::RenderUnitReply {
            index: 3,
            // Radiance sums between 0.5 and 2 and zero weight sums: what every pixel may hold.
            pixels: (0..pixels * BYTES_PER_PIXEL)
                .map(|i| match (i % BYTES_PER_PIXEL, i % 4) {
                    (12.., _) => 0,
                    (_, 3) => 0x3f,
                    _ => (i * 7) as u8,
                })
                .collect::<Vec<u8>>()
                .into(),
            stats: Some(pb::UnitStats {
                samples: 64,
                rays: 200,
                dropped: 1,
            }),
            render_seconds: 0.25,
            // A film with light splats (odd seeds) takes a few, anywhere on it.
            light_splats: match seed % 2 {
                1 => encode_splats(&LightSplats {
                    pixels: vec![0, width + 1, width * height - 1],
                    rgb: vec![[0.5, 1.0, 2.0], [0.0; 3], [1e3, 0.0, 7.0]],
                }),
                _ => Default::default(),
            },
            // Alpha sums of zero (seeds with the second bit): what every pixel may hold.
            layers: vec![0u8; if seed & 2 != 0 { pixels * 4 } else { 0 }].into(),
        };
        sessions.push(Session {
            frames: vec![
                frame(
                    Kind::HandshakeRequest,
                    pb::HandshakeRequest {
                        protocol_version: PROTOCOL_VERSION,
                        client: "coordinator".into(),
                    }
                    .encode_to_vec(),
                ),
                frame(
                    Kind::HasBlobsRequest,
                    pb::HasBlobsRequest {
                        sha256: vec![hash.clone(), "not-a-hash".into()],
                    }
                    .encode_to_vec(),
                ),
                frame(
                    Kind::BlobChunk,
                    pb::BlobChunk {
                        sha256: hash.clone(),
                        size: 20,
                        data: b"WorldBegin\nWorldEnd\n".to_vec().into(),
                    }
                    .encode_to_vec(),
                ),
                frame(Kind::LoadSceneRequest, load.encode_to_vec()),
                frame(
                    Kind::RenderUnitRequest,
                    pb::RenderUnitRequest {
                        scene_id: hash.clone(),
                        unit: Some(unit),
                    }
                    .encode_to_vec(),
                ),
                frame(Kind::RenderUnitReply, reply.encode_to_vec()),
            ],
        });
    }
    sessions.push(Session {
        frames: vec![
            frame(
                Kind::HandshakeReply,
                pb::HandshakeReply {
                    protocol_version: PROTOCOL_VERSION,
                    threads: 2,
                    hostname: "node-1".into(),
                    max_message_bytes: 8 << 20,
                    max_blob_bytes: 1 << 30,
                    features: vec!["tls".into(), "disk-cache".into()],
                    software: "yat 0.1.0".into(),
                    renderer_build: yat_tracer::RENDERER_BUILD.into(),
                }
                .encode_to_vec(),
            ),
            frame(
                Kind::HasBlobsReply,
                pb::HasBlobsReply {
                    missing: vec![sha256_hex(b"x")],
                }
                .encode_to_vec(),
            ),
            frame(
                Kind::PutBlobReply,
                pb::PutBlobReply { stored_bytes: 20 }.encode_to_vec(),
            ),
            frame(
                Kind::LoadSceneReply,
                pb::LoadSceneReply {
                    scene_id: sha256_hex(b"scene"),
                    triangle_count: 12,
                    build_seconds: 0.5,
                    warnings: vec!["main.lxs:3:1: warning: x".into()],
                }
                .encode_to_vec(),
            ),
            frame(Kind::StatsRequest, pb::StatsRequest {}.encode_to_vec()),
            frame(
                Kind::StatsReply,
                pb::StatsReply {
                    units_done: 3,
                    samples_done: 1000,
                    blob_bytes_received: 20,
                    result_bytes_sent: 4096,
                    blobs_cached: 1,
                    scenes_cached: 1,
                    units_in_flight: 0,
                    uptime_seconds: 12.5,
                }
                .encode_to_vec(),
            ),
            frame(Kind::Authorization, format!("Bearer {TOKEN}").into_bytes()),
            frame(Kind::Authorization, b"Bearer wrong".to_vec()),
            frame(
                Kind::StatusTrailers,
                b"14\0worker draining: unit 3 refused\x001".to_vec(),
            ),
            frame(Kind::StatusTrailers, b"13\0internal%20error".to_vec()),
        ],
    });
    sessions
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_seed_sessions_take_the_deep_paths() {
        let target = WireTarget::new();
        let first = target.execute(&target.corpus[0]).features;
        // Settings accepted, unit accepted, reply (with light splats and alpha: seed 7) merged
        // into the film and displayed.
        let load = Kind::LoadSceneRequest as u64 * 16;
        let unit = Kind::RenderUnitRequest as u64 * 16;
        let reply = Kind::RenderUnitReply as u64 * 16;
        assert!(first.contains(&(load + 4)), "{first:?}");
        assert!(first.contains(&(unit + 3)), "{first:?}");
        assert!(
            first.contains(&(reply + 10)) || first.contains(&(reply + 9)),
            "{first:?}"
        );
        let last = target.execute(target.corpus.last().unwrap()).features;
        let auth = Kind::Authorization as u64 * 16;
        assert!(
            last.contains(&(auth + 2)) && last.contains(&(auth + 1)),
            "{last:?}"
        );
        let trailers = Kind::StatusTrailers as u64 * 16;
        assert!(last.contains(&(trailers + 8)), "a drain is seen: {last:?}");
    }

    #[test]
    fn a_session_encodes_and_decodes_to_itself() {
        for s in seed_sessions() {
            assert_eq!(Session::decode(&s.encode()), Some(s));
        }
    }

    #[test]
    fn protobuf_fields_parse_and_mutate_into_other_messages() {
        let bytes = pb::WorkUnit {
            index: 1,
            x0: 2,
            y0: 3,
            x1: 4,
            y1: 5,
            sample_start: 6,
            sample_end: 7,
            block_mask: None,
        }
        .encode_to_vec();
        assert_eq!(parse_fields(&bytes).unwrap().len(), 7);
        let mut rng = Rng::with_seed(1);
        let mut differ = 0;
        for _ in 0..100 {
            let mut m = bytes.clone();
            mutate_protobuf(&mut rng, &mut m, 0);
            differ += usize::from(
                pb::WorkUnit::decode(&m[..]).ok() != pb::WorkUnit::decode(&bytes[..]).ok(),
            );
        }
        assert!(differ > 80, "{differ} of 100 mutations changed the message");
    }
}
