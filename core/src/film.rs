//! The film: per-pixel sums of radiance samples and their counts (box filter: a sample lands
//! in its own pixel), and writing it out atomically as linear EXR or sRGB PNG.

use crate::Rgb;
use crate::error::{Error, Result};
use std::path::Path;

#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    sum: Vec<[f64; 3]>,
    count: Vec<u32>,
    /// Rays traced to make the image (statistics; 0 if the integrator does not count).
    pub rays: u64,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Film {
        let n = width as usize * height as usize;
        Film {
            width,
            height,
            sum: vec![[0.0; 3]; n],
            count: vec![0; n],
            rays: 0,
        }
    }

    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }

    #[inline]
    pub fn add_sample(&mut self, x: u32, y: u32, radiance: Rgb) {
        let i = self.index(x, y);
        let s = &mut self.sum[i];
        s[0] += radiance.x as f64;
        s[1] += radiance.y as f64;
        s[2] += radiance.z as f64;
        self.count[i] += 1;
    }

    /// Adds a pixel's accumulated sum and count (used when merging tiles).
    pub fn add_pixel(&mut self, i: usize, sum: [f64; 3], count: u32) {
        let s = &mut self.sum[i];
        for c in 0..3 {
            s[c] += sum[c];
        }
        self.count[i] += count;
    }

    /// Sets a pixel's value directly as if from one sample (for integrators that produce
    /// whole estimates, e.g. progressive photon mapping).
    pub fn set_pixel(&mut self, x: u32, y: u32, value: Rgb) {
        let i = self.index(x, y);
        self.sum[i] = [value.x as f64, value.y as f64, value.z as f64];
        self.count[i] = 1;
    }

    pub fn sample_count(&self, x: u32, y: u32) -> u32 {
        self.count[self.index(x, y)]
    }

    pub fn total_samples(&self) -> u64 {
        self.count.iter().map(|&c| c as u64).sum()
    }

    /// Pixel value: the mean of its samples, each pixel divided by its own count (an
    /// interrupted render has pixels with different counts); black without samples.
    pub fn pixel(&self, x: u32, y: u32) -> Rgb {
        let i = self.index(x, y);
        let n = self.count[i];
        if n == 0 {
            return Rgb::ZERO;
        }
        let s = self.sum[i];
        Rgb::new(
            (s[0] / n as f64) as f32,
            (s[1] / n as f64) as f32,
            (s[2] / n as f64) as f32,
        )
    }

    /// All pixels, row-major from the top-left.
    pub fn pixels(&self) -> Vec<Rgb> {
        (0..self.height)
            .flat_map(|y| (0..self.width).map(move |x| (x, y)))
            .map(|(x, y)| self.pixel(x, y))
            .collect()
    }

    /// Mean of all pixel values.
    pub fn mean(&self) -> Rgb {
        let px = self.pixels();
        let sum: glam::DVec3 = px.iter().map(|p| p.as_dvec3()).sum();
        (sum / px.len().max(1) as f64).as_vec3()
    }

    pub fn write(&self, path: &Path) -> Result<()> {
        write_image(path, self.width, self.height, &self.pixels())
    }
}

/// sRGB transfer curve (IEC 61966-2-1) of a linear value in [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    let c = linear.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`srgb_encode`]: the linear value of an sRGB-encoded one in [0, 1].
pub fn srgb_decode(encoded: f32) -> f32 {
    let c = encoded.clamp(0.0, 1.0);
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The format an output path asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Exr,
    Png,
}

pub fn format_of(path: &Path) -> Result<ImageFormat> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .as_deref()
    {
        Some("exr") => Ok(ImageFormat::Exr),
        Some("png") => Ok(ImageFormat::Png),
        _ => Err(Error::io(
            path,
            "unsupported output format: use .exr (linear float32) or .png (sRGB 8-bit)",
        )),
    }
}

/// Checks before rendering that an output can be written: known extension, existing and
/// writable folder. Finding out after a long render would lose it.
pub fn check_output(path: &Path) -> Result<()> {
    format_of(path)?;
    if path.exists() && !path.is_file() {
        return Err(Error::io(
            path,
            "the output exists and is not a regular file",
        ));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if dir.exists() && !dir.is_dir() {
        return Err(Error::io(
            path,
            format!("{} is not a folder", dir.display()),
        ));
    }
    if !dir.is_dir() {
        return Err(Error::io(
            path,
            format!("output folder {} does not exist", dir.display()),
        ));
    }
    let probe = dir.join(format!(".foton-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| {
        Error::io(
            path,
            format!("output folder {} is not writable: {e}", dir.display()),
        )
    })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Writes linear RGB pixels (row-major, top-left first): EXR as linear float32, PNG as 8-bit
/// sRGB. Atomic: written to a temporary file in the same folder, then renamed over `path`.
pub fn write_image(path: &Path, width: u32, height: u32, pixels: &[Rgb]) -> Result<()> {
    let format = format_of(path)?;
    let file_name = path
        .file_name()
        .ok_or_else(|| Error::io(path, "not a file name"))?
        .to_string_lossy();
    let tmp = path.with_file_name(format!(".{file_name}.tmp-{}", std::process::id()));
    let result = match format {
        ImageFormat::Exr => {
            let data: Vec<f32> = pixels.iter().flat_map(|p| p.to_array()).collect();
            let img = image::Rgb32FImage::from_raw(width, height, data)
                .ok_or_else(|| Error::io(path, "pixel buffer has the wrong size"))?;
            image::DynamicImage::ImageRgb32F(img)
                .save_with_format(&tmp, image::ImageFormat::OpenExr)
        }
        ImageFormat::Png => {
            let data: Vec<u8> = pixels
                .iter()
                .flat_map(|p| p.to_array())
                .map(|c| (srgb_encode(c) * 255.0 + 0.5) as u8)
                .collect();
            let img = image::RgbImage::from_raw(width, height, data)
                .ok_or_else(|| Error::io(path, "pixel buffer has the wrong size"))?;
            img.save_with_format(&tmp, image::ImageFormat::Png)
        }
    };
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path, e)
    })
}

/// Reads an image as linear RGB (EXR as stored; PNG decoded from sRGB).
pub fn read_image(path: &Path) -> Result<(u32, u32, Vec<Rgb>)> {
    let img = image::open(path).map_err(|e| Error::io(path, e))?;
    let is_png = format_of(path).ok() == Some(ImageFormat::Png);
    let rgb = img.to_rgb32f();
    let (w, h) = rgb.dimensions();
    let decode = |c: f32| if is_png { srgb_decode(c) } else { c };
    let px = rgb
        .pixels()
        .map(|p| Rgb::new(decode(p.0[0]), decode(p.0[1]), decode(p.0[2])))
        .collect();
    Ok((w, h, px))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_decode_inverts_encode() {
        for i in 0..=1000 {
            let x = i as f32 / 1000.0;
            assert!((srgb_decode(srgb_encode(x)) - x).abs() < 1e-5, "{x}");
        }
        assert_eq!(srgb_decode(0.0), 0.0);
        assert!((srgb_decode(1.0) - 1.0).abs() < 1e-6);
    }
}
