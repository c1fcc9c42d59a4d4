//! Lanes benchmark: how much faster a path tracer runs when each
//! instruction advances 8 or 16 paths, and whether that can keep an image's bits on every CPU.
//!
//! One path tracer (`tracer.rs`) is written once over a lane type (`lanes.rs`) and run as: one
//! path at a time (`f32`); eight paths in AVX2 registers through `std::arch` intrinsics; eight
//! or sixteen in arrays whose loops the compiler vectorises, for AVX2, AVX-512 (when the CPU has
//! it) and baseline x86-64. Each vector variant runs twice: with closest hits in lanes too, and
//! with closest hits one live lane at a time through the scalar code, as a renderer whose BVH
//! traversal stays per ray would run. Prints the best time of the rounds (one thread), samples/s,
//! rays/s, the lanes' occupancy and the speed-up over one path at a time, and fails unless
//! every variant's image has the scalar image's bits.
//!
//! `cargo run --release -p yat-lanes -- --rounds 5 [--output lanes.png]`

mod tracer;

use std::time::Instant;

use anyhow::{ensure, Context, Result};
use clap::Parser;

use tracer::{render, Counts, Scene, Traversal};
use yat_tracer::lanes::Arr;

#[derive(Parser)]
struct Args {
    #[arg(long, default_value_t = 480)]
    width: usize,
    #[arg(long, default_value_t = 270)]
    height: usize,
    /// Samples per pixel, a multiple of 16.
    #[arg(long, default_value_t = 16)]
    spp: usize,
    /// Rounds; each variant's best is reported (the variants alternate within a round).
    #[arg(long, default_value_t = 3)]
    rounds: usize,
    /// Also write the scalar image here (PNG, gamma 2.2, x / (1 + x) tone curve).
    #[arg(long)]
    output: Option<std::path::PathBuf>,
}

type Image = Vec<[f32; 3]>;
type RenderFn = fn(&Scene, usize, Traversal) -> (Image, Counts);

struct Variant {
    name: &'static str,
    render: RenderFn,
}

fn scalar(scene: &Scene, spp: usize, traversal: Traversal) -> (Image, Counts) {
    render::<f32>(scene, spp, traversal)
}

fn arrays_baseline(scene: &Scene, spp: usize, traversal: Traversal) -> (Image, Counts) {
    render::<Arr<8>>(scene, spp, traversal)
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::*;
    use yat_tracer::lanes::{Avx2Cpu, Lanes, OnLanes};

    /// The render on the lane type `OnLanes` picks.
    struct Render<'a> {
        scene: &'a Scene,
        spp: usize,
        traversal: Traversal,
    }

    impl OnLanes for Render<'_> {
        type Output = (Image, Counts);

        #[inline(always)]
        fn run<L: Lanes>(&self) -> Self::Output {
            render::<L>(self.scene, self.spp, self.traversal)
        }
    }

    fn intrinsics_avx2(scene: &Scene, spp: usize, traversal: Traversal) -> (Image, Counts) {
        let cpu = Avx2Cpu::detect().expect("listed only where the CPU has AVX2");
        cpu.run(&Render {
            scene,
            spp,
            traversal,
        })
    }

    #[target_feature(enable = "avx2")]
    fn arrays_avx2(scene: &Scene, spp: usize, traversal: Traversal) -> (Image, Counts) {
        render::<Arr<8>>(scene, spp, traversal)
    }

    #[target_feature(enable = "avx512f")]
    fn arrays_avx512(scene: &Scene, spp: usize, traversal: Traversal) -> (Image, Counts) {
        render::<Arr<16>>(scene, spp, traversal)
    }

    /// The variants this CPU can run.
    pub fn variants() -> Vec<Variant> {
        let mut out = Vec::new();
        if is_x86_feature_detected!("avx2") {
            out.push(Variant {
                name: "AVX2 intrinsics, 8 lanes",
                render: intrinsics_avx2,
            });
            out.push(Variant {
                name: "arrays of 8, AVX2",
                // SAFETY: the CPU has AVX2.
                render: |s, spp, t| unsafe { arrays_avx2(s, spp, t) },
            });
        }
        if is_x86_feature_detected!("avx512f") {
            out.push(Variant {
                name: "arrays of 16, AVX-512",
                // SAFETY: the CPU has AVX-512F.
                render: |s, spp, t| unsafe { arrays_avx512(s, spp, t) },
            });
        }
        out
    }
}

fn variants() -> Vec<Variant> {
    let baseline = Variant {
        name: "arrays of 8, baseline",
        render: arrays_baseline,
    };
    #[cfg(target_arch = "x86_64")]
    return std::iter::once(baseline).chain(x86::variants()).collect();
    #[cfg(not(target_arch = "x86_64"))]
    vec![baseline]
}

/// Pixels whose bits differ.
fn differing(a: &Image, b: &Image) -> usize {
    a.iter()
        .zip(b)
        .filter(|(x, y)| x.map(f32::to_bits) != y.map(f32::to_bits))
        .count()
}

fn main() -> Result<()> {
    let args = Args::parse();
    ensure!(
        args.spp.is_multiple_of(16) && (16..=256).contains(&args.spp),
        "--spp must be a multiple of 16 up to 256"
    );
    let scene = Scene::new(args.width, args.height);
    let mut runs: Vec<(String, RenderFn, Traversal)> = vec![(
        "one path at a time".into(),
        scalar as RenderFn,
        Traversal::Lanes,
    )];
    for v in variants() {
        runs.push((v.name.to_string(), v.render, Traversal::Lanes));
        runs.push((
            format!("{}, closest hits by lane", v.name),
            v.render,
            Traversal::ByLane,
        ));
    }
    let mut best = vec![f64::INFINITY; runs.len()];
    let mut results: Vec<Option<(Image, Counts)>> = vec![None; runs.len()];
    for _ in 0..args.rounds {
        for (i, (_, run, traversal)) in runs.iter().enumerate() {
            let start = Instant::now();
            let out = run(&scene, args.spp, *traversal);
            best[i] = best[i].min(start.elapsed().as_secs_f64());
            results[i].get_or_insert(out);
        }
    }
    let samples = (args.width * args.height * args.spp) as f64;
    let (reference, _) = results[0].as_ref().expect("one round at least");
    println!(
        "{}x{} {} spp, depth {}, one thread, best of {} rounds",
        args.width,
        args.height,
        args.spp,
        tracer::MAX_DEPTH,
        args.rounds
    );
    println!(
        "| variant | s | M samples/s | M rays/s | occupancy | speed-up | pixels unlike scalar |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut unlike = 0;
    for (i, (name, _, _)) in runs.iter().enumerate() {
        let (image, counts) = results[i].as_ref().expect("one round at least");
        let differ = differing(reference, image);
        unlike += differ;
        println!(
            "| {name} | {:.3} | {:.2} | {:.2} | {:.0}% | {:.2}x | {differ} |",
            best[i],
            samples / best[i] / 1e6,
            counts.rays as f64 / best[i] / 1e6,
            100.0 * counts.rays as f64 / counts.lane_steps.max(1) as f64,
            best[0] / best[i],
        );
    }
    ensure!(unlike == 0, "{unlike} pixels differ from the scalar image");
    if let Some(path) = &args.output {
        let bytes = reference
            .iter()
            .flat_map(|p| p.map(|c| (libm::powf(c / (1.0 + c), 1.0 / 2.2) * 255.0) as u8))
            .collect();
        let png = image::RgbImage::from_raw(args.width as u32, args.height as u32, bytes)
            .context("image size")?;
        png.save(path)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_lane_type_gives_the_scalar_bits() {
        let scene = Scene::new(24, 14);
        let (reference, counts) = scalar(&scene, 16, Traversal::Lanes);
        let mean = reference.iter().map(|p| p[0] + p[1] + p[2]).sum::<f32>()
            / (3 * reference.len()) as f32;
        assert!(
            (0.005..0.5).contains(&mean) && counts.rays > 2 * reference.len() as u64 * 16,
            "mean {mean}, {} rays",
            counts.rays
        );
        for v in variants() {
            for traversal in [Traversal::Lanes, Traversal::ByLane] {
                let (image, lane_counts) = (v.render)(&scene, 16, traversal);
                assert_eq!(differing(&reference, &image), 0, "{}", v.name);
                assert_eq!(lane_counts.rays, counts.rays, "{}", v.name);
            }
        }
    }
}
