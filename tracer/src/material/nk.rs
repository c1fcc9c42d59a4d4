//! Metal refractive-index data files (`.nk`), which `Material "metal" "string name"` (or
//! `"string filename"`) may name instead of a preset: the complex index n + i k by wavelength,
//! reduced to RGB by sampling at [`RGB_WAVELENGTHS`] as the built-in presets are.
//!
//! Two formats, as LuxRender reads them:
//! - SOPRA: a header `unit first last count` (unit 1 eV, 2 micrometres, 3 inverse cm, 4 nm),
//!   then `count` lines `n k` at evenly spaced values from `first` to `last`.
//! - Luxpop: lines `wavelength n k` with the wavelength in angstroms; lines starting with `;`
//!   are comments.
//!
//! LuxRender spaces SOPRA samples by `(last - first) / count` and pairs the first line with the
//! `last` value for micrometre files; YAT spaces them to end on `last` in every unit. A file is
//! bounded to [`MAX_SAMPLES`] samples; any malformed line is an error naming its number.

use glam::Vec3;

/// Where the R, G and B channels sample a spectrum, in nm.
pub const RGB_WAVELENGTHS: [f32; 3] = [650.0, 550.0, 450.0];
/// Planck's constant times the speed of light in eV nm: a photon of E eV has wavelength
/// HC / E nm.
pub const HC_EV_NM: f64 = 1_239.841_984;
/// The most samples a file may hold.
pub const MAX_SAMPLES: usize = 100_000;

/// What is wrong with a file, and on which line (1-based; 0 for the file as a whole).
#[derive(Debug, Clone, PartialEq)]
pub struct NkError {
    pub line: usize,
    pub message: String,
}

fn error(line: usize, message: impl Into<String>) -> NkError {
    NkError {
        line,
        message: message.into(),
    }
}

/// Numbers of one line, or an error naming it.
fn numbers(line: usize, text: &str) -> Result<Vec<f64>, NkError> {
    text.split_whitespace()
        .map(|t| {
            t.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| error(line, format!("\"{t}\" is not a number")))
        })
        .collect()
}

/// The SOPRA header's unit code as a conversion to nm.
fn unit_to_nm(code: f64) -> Option<fn(f64) -> f64> {
    Some(match code as i64 {
        1 if code == 1.0 => |ev| HC_EV_NM / ev,
        2 if code == 2.0 => |um| um * 1000.0,
        3 if code == 3.0 => |inv_cm| 1e7 / inv_cm,
        4 if code == 4.0 => |nm| nm,
        _ => return None,
    })
}

/// (wavelength nm, n, k) samples of the file's text.
fn samples(text: &str) -> Result<Vec<(f64, f64, f64)>, NkError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with(';'));
    let Some((first_no, first)) = lines.next() else {
        return Err(error(0, "no data"));
    };
    let header = numbers(first_no, first)?;
    let sopra = header.len() == 4 && header[3].fract() == 0.0 && header[3] >= 1.0;
    let mut out = Vec::new();
    if sopra {
        let to_nm = unit_to_nm(header[0])
            .ok_or_else(|| error(first_no, "unit must be 1 (eV), 2 (um), 3 (1/cm) or 4 (nm)"))?;
        let count = header[3] as usize;
        if count > MAX_SAMPLES {
            return Err(error(first_no, format!("more than {MAX_SAMPLES} samples")));
        }
        let (start, end) = (header[1], header[2]);
        for j in 0..count {
            let (no, line) = lines
                .next()
                .ok_or_else(|| error(0, format!("{count} samples announced, {j} found")))?;
            let v = numbers(no, line)?;
            if v.len() != 2 {
                return Err(error(no, "expected \"n k\""));
            }
            let t = if count > 1 {
                j as f64 / (count - 1) as f64
            } else {
                0.0
            };
            out.push((to_nm(start + (end - start) * t), v[0], v[1]));
        }
    } else {
        for (no, line) in std::iter::once((first_no, first)).chain(lines) {
            let v = numbers(no, line)?;
            if v.len() != 3 {
                return Err(error(no, "expected \"wavelength n k\""));
            }
            if out.len() == MAX_SAMPLES {
                return Err(error(no, format!("more than {MAX_SAMPLES} samples")));
            }
            // Angstroms to nm.
            out.push((v[0] * 0.1, v[1], v[2]));
        }
    }
    if let Some(bad) = out
        .iter()
        .find(|(wl, n, k)| !(wl.is_finite() && *wl > 0.0 && *n >= 0.0 && *k >= 0.0))
    {
        return Err(error(
            0,
            format!(
                "a sample ({:.1} nm, n {}, k {}) is out of range",
                bad.0, bad.1, bad.2
            ),
        ));
    }
    Ok(out)
}

/// Linear interpolation of the samples (sorted by wavelength) at `nm`, held flat beyond
/// either end.
fn at(samples: &[(f64, f64, f64)], nm: f64) -> (f64, f64) {
    let i = samples.partition_point(|s| s.0 < nm);
    if i == 0 {
        return (samples[0].1, samples[0].2);
    }
    if i == samples.len() {
        let s = samples[i - 1];
        return (s.1, s.2);
    }
    let (a, b) = (samples[i - 1], samples[i]);
    let t = if b.0 > a.0 {
        (nm - a.0) / (b.0 - a.0)
    } else {
        0.0
    };
    (a.1 + (b.1 - a.1) * t, a.2 + (b.2 - a.2) * t)
}

/// The (wavelength nm, n, k) samples of an `.nk` file's bytes, sorted by wavelength.
fn sorted_samples(bytes: &[u8]) -> Result<Vec<(f64, f64, f64)>, NkError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1;
        error(line, "not UTF-8 text")
    })?;
    let mut samples = samples(text)?;
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(samples)
}

/// The real part of the index by wavelength, `(nm, n)` sorted by wavelength, of an `.nk`
/// file's bytes: what the `sopra` and `luxpop` fresnel textures give a volume (glass2 refracts
/// with n alone).
pub fn read_index(bytes: &[u8]) -> Result<Vec<(f32, f32)>, NkError> {
    Ok(sorted_samples(bytes)?
        .into_iter()
        .map(|(nm, n, _)| (nm as f32, n as f32))
        .collect())
}

/// The (eta, k) per RGB channel of an `.nk` file's bytes.
pub fn read(bytes: &[u8]) -> Result<(Vec3, Vec3), NkError> {
    let samples = sorted_samples(bytes)?;
    let (mut eta, mut k) = (Vec3::ZERO, Vec3::ZERO);
    for (c, nm) in RGB_WAVELENGTHS.iter().enumerate() {
        let (n, kk) = at(&samples, f64::from(*nm));
        eta[c] = n as f32;
        k[c] = kk as f32;
    }
    Ok((eta, k))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn luxpop_file_is_interpolated_at_the_rgb_wavelengths() {
        let text =
            "; gold-ish\n4000 1.5 1.9\n5000 0.9 1.8\n; mid comment\n6000 0.3 3.0\n7000 0.2 4.0\n";
        let (eta, k) = read(text.as_bytes()).unwrap();
        // 650 nm halfway between 600 and 700; 550 between 500 and 600; 450 between 400 and 500.
        assert!(
            (eta - Vec3::new(0.25, 0.6, 1.2)).abs().max_element() < 1e-6,
            "{eta}"
        );
        assert!(
            (k - Vec3::new(3.5, 2.4, 1.85)).abs().max_element() < 1e-6,
            "{k}"
        );
    }

    #[test]
    fn sopra_file_in_each_unit() {
        // nm: 3 samples 400, 550, 700.
        let (eta, k) = read(b"4 400 700 3\n1.0 2.0\n2.0 3.0\n3.0 4.0\n").unwrap();
        assert!(
            (eta - Vec3::new(2.666_666_7, 2.0, 1.333_333_4))
                .abs()
                .max_element()
                < 1e-5
        );
        assert!(
            (k - Vec3::new(3.666_666_7, 3.0, 2.333_333_4))
                .abs()
                .max_element()
                < 1e-5
        );
        // eV: 1239.84/2.2542 = 550 nm exactly in the middle sample.
        let ev = HC_EV_NM / 550.0;
        let text = format!("1 {} {} 3\n5 5\n7 8\n9 9\n", ev - 0.5, ev + 0.5);
        let (eta, k) = read(text.as_bytes()).unwrap();
        assert!(
            (eta.y - 7.0).abs() < 1e-4 && (k.y - 8.0).abs() < 1e-4,
            "{eta} {k}"
        );
        // Micrometres: 0.45 .. 0.65 in 3 steps.
        let (eta, _) = read(b"2 0.45 0.65 3\n1 0\n2 0\n3 0\n").unwrap();
        assert!(
            (eta - Vec3::new(3.0, 2.0, 1.0)).abs().max_element() < 1e-5,
            "{eta}"
        );
    }

    #[test]
    fn malformed_files_name_the_line() {
        let cases: [(&[u8], usize); 7] = [
            (b"4000 1.5 1.9\n5000 x 1.8\n", 2),
            (b"4000 1.5 1.9\n\n5000 1.8\n", 3),
            (b"4 400 700 3\n1 2\n2 3\n", 0),
            (b"9 400 700 3\n1 2\n2 3\n3 4\n", 1),
            (b"", 0),
            (b"4000 1.5 -1\n", 0),
            (b"4000 1.5 1\n\xff\n", 2),
        ];
        for (bytes, line) in cases {
            let e = read(bytes).unwrap_err();
            assert_eq!(e.line, line, "{:?}: {e:?}", String::from_utf8_lossy(bytes));
        }
        let huge = format!("4 400 700 {}\n", MAX_SAMPLES + 1);
        assert_eq!(read(huge.as_bytes()).unwrap_err().line, 1);
    }
}
