//! Compares two renders of the same scene (before/after a traversal change): whether the EXR
//! files are byte-identical, and otherwise the ratio of their mean values and the mean squared
//! error over all RGB channels.
//!
//! `cargo run --release -p yat-traversal --bin exr-diff -- old.exr new.exr`

use anyhow::{ensure, Context, Result};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    ensure!(args.len() == 2, "usage: exr-diff OLD.exr NEW.exr");
    let (a, b) = (std::fs::read(&args[0])?, std::fs::read(&args[1])?);
    if a == b {
        println!("byte-identical");
        return Ok(());
    }
    let decode = |bytes: &[u8], name: &str| -> Result<Vec<f32>> {
        let img = image::load_from_memory_with_format(bytes, image::ImageFormat::OpenExr)
            .with_context(|| format!("cannot decode {name}"))?;
        Ok(img.to_rgb32f().into_raw())
    };
    let (a, b) = (decode(&a, &args[0])?, decode(&b, &args[1])?);
    ensure!(a.len() == b.len(), "different sizes");
    let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64;
    let mse = a
        .iter()
        .zip(&b)
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2))
        .sum::<f64>()
        / a.len() as f64;
    let differing = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    println!(
        "mean ratio new/old {:.6}, MSE {mse:.3e}, {differing} of {} channel values differ",
        mean(&b) / mean(&a),
        a.len()
    );
    Ok(())
}
