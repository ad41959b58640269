//! Image files: a film or linear RGB pixels written atomically as linear EXR or sRGB PNG (the
//! conventions are core's [`foton_core::film`]: [`DisplayTransform`], [`format_of`]), and an
//! image read back as linear RGB. The codecs (`image`, `exr`) are linked here, not by core.

use foton_core::Rgb;
use foton_core::error::{Error, Result};
use foton_core::film::{DisplayTransform, Film, ImageFormat, format_of, srgb_decode};
use std::path::Path;

/// Writing a [`Film`] to a file (a trait on core's type, so that `film.write(...)` reads as
/// before where it is in scope).
pub trait FilmFile {
    /// Writes the image atomically: an EXR as linear radiance, a PNG through `display`.
    fn write(&self, path: &Path, display: &DisplayTransform) -> Result<()>;
}

impl FilmFile for Film {
    fn write(&self, path: &Path, display: &DisplayTransform) -> Result<()> {
        if self.layers().is_empty() {
            return write_image(path, self.width, self.height, &self.pixels(), display);
        }
        if format_of(path)? != ImageFormat::Exr {
            return Err(Error::io(
                path,
                "the technique layers can only be written to an EXR: name the output .exr",
            ));
        }
        let layers: Vec<(&str, Vec<Rgb>)> = (self.layers().iter().enumerate())
            .map(|(k, l)| (l.name.as_str(), self.layer_pixels(k)))
            .collect();
        write_exr_layers(path, self.width, self.height, &self.pixels(), &layers)
    }
}

/// Writes linear RGB pixels as an EXR's R, G, B channels, and each of `layers` as channels
/// `<name>.R`, `<name>.G`, `<name>.B` of the same image (the multi-layer convention of one
/// EXR part, as renderers write their AOVs): float32, atomically.
pub fn write_exr_layers(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[Rgb],
    layers: &[(&str, Vec<Rgb>)],
) -> Result<()> {
    use exr::prelude::{
        AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, SmallVec,
        WritableImage,
    };
    let n = width as usize * height as usize;
    if pixels.len() != n || layers.iter().any(|(_, p)| p.len() != n) {
        return Err(Error::io(path, "pixel buffer has the wrong size"));
    }
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::with_capacity(3 * (layers.len() + 1));
    let mut push = |prefix: &str, pixels: &[Rgb]| {
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            let values = pixels.iter().map(|p| p[c]).collect();
            channels.push(AnyChannel::new(
                format!("{prefix}{name}").as_str(),
                FlatSamples::F32(values),
            ));
        }
    };
    push("", pixels);
    for (name, pixels) in layers {
        push(&format!("{name}."), pixels);
    }
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let file_name = path
        .file_name()
        .ok_or_else(|| Error::io(path, "not a file name"))?
        .to_string_lossy();
    let tmp = path.with_file_name(format!(".{file_name}.tmp-{}", std::process::id()));
    if let Err(e) = Image::from_layer(layer).write().to_file(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e.to_string()));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path, e)
    })
}

/// Writes linear RGB pixels (row-major, top-left first): EXR as linear float32, unchanged
/// (`display` is not applied: an EXR keeps the radiance); PNG as 8-bit sRGB of the pixels
/// through `display`. Atomic: written to a temporary file in the same folder, then renamed
/// over `path`.
pub fn write_image(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[Rgb],
    display: &DisplayTransform,
) -> Result<()> {
    let format = format_of(path)?;
    let file_name = path
        .file_name()
        .ok_or_else(|| Error::io(path, "not a file name"))?
        .to_string_lossy();
    let tmp = path.with_file_name(format!(".{file_name}.tmp-{}", std::process::id()));
    let result = match format {
        ImageFormat::Exr => {
            if pixels.len() != width as usize * height as usize {
                return Err(Error::io(path, "pixel buffer has the wrong size"));
            }
            // exr directly rather than through `image`, whose encoder writes compressed
            // blocks in the order threads finish them: the same pixels must make the same
            // bytes (a merged render is compared with the one-process render by its bytes).
            use exr::prelude::{
                Encoding, Image, Layer, LayerAttributes, SpecificChannels, Vec2, WritableImage,
            };
            let w = width as usize;
            let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
                let p = pixels[y * w + x];
                (p.x, p.y, p.z)
            });
            let layer = Layer::new(
                (w, height as usize),
                LayerAttributes::default(),
                Encoding::SMALL_LOSSLESS,
                channels,
            );
            Image::from_layer(layer)
                .write()
                .to_file(&tmp)
                .map_err(|e| image::ImageError::IoError(std::io::Error::other(e.to_string())))
        }
        ImageFormat::Png => {
            let data: Vec<u8> = pixels.iter().flat_map(|p| display.encode(*p)).collect();
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

/// An image's channels by name, each its values row-major.
pub type Channels = Vec<(String, Vec<f32>)>;

/// Reads every float channel of an EXR's first image, by name (`R`, `G`, `B` and the technique
/// layers' `<name>.R`...), in the file's (alphabetical) order; its width and height.
pub fn read_exr_channels(path: &Path) -> Result<(u32, u32, Channels)> {
    use exr::prelude::{FlatSamples, read_all_flat_layers_from_file};
    let image = read_all_flat_layers_from_file(path).map_err(|e| Error::io(path, e.to_string()))?;
    let layer = image
        .layer_data
        .first()
        .ok_or_else(|| Error::io(path, "an EXR without any image"))?;
    let channels = (layer.channel_data.list.iter())
        .map(|c| {
            let values = match &c.sample_data {
                FlatSamples::F32(v) => v.clone(),
                FlatSamples::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
                FlatSamples::U32(v) => v.iter().map(|&x| x as f32).collect(),
            };
            (c.name.to_string(), values)
        })
        .collect();
    let (w, h) = (layer.size.0 as u32, layer.size.1 as u32);
    Ok((w, h, channels))
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
    use foton_core::film::ToneMap;

    #[test]
    fn png_goes_through_the_display_transform_and_exr_does_not() {
        let dir = std::env::temp_dir().join(format!("foton-film-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let pixels = [Rgb::new(0.2, 1.0, 3.0), Rgb::new(0.02, 0.5, 100.0)];
        let display = DisplayTransform::new(-1.5, ToneMap::Filmic);
        let png = dir.join("a.png");
        write_image(&png, 2, 1, &pixels, &display).unwrap();
        let bytes = image::open(&png).unwrap().to_rgb8().into_raw();
        let expected: Vec<u8> = pixels.iter().flat_map(|p| display.encode(*p)).collect();
        assert_eq!(bytes, expected);
        // And that is not the plain clip: the transform was applied.
        assert_ne!(bytes[..3], DisplayTransform::default().encode(pixels[0]));
        let exr = dir.join("a.exr");
        write_image(&exr, 2, 1, &pixels, &display).unwrap();
        assert_eq!(read_image(&exr).unwrap().2, pixels);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The same pixels make the same bytes: an EXR of many compressed blocks (compressed in
    /// parallel) is written in a fixed block order.
    #[test]
    fn an_exr_is_the_same_bytes_every_time() {
        let dir = std::env::temp_dir().join(format!("foton-film-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (w, h) = (320u32, 240u32);
        let mut rng = foton_core::sampling::Rng::new(&[3]);
        let pixels: Vec<Rgb> = (0..w * h)
            .map(|_| Rgb::new(rng.next_f32(), rng.next_f32() * 10.0, rng.next_f32() * 0.1))
            .collect();
        let write = |name: &str| {
            let path = dir.join(name);
            write_image(&path, w, h, &pixels, &DisplayTransform::default()).unwrap();
            std::fs::read(path).unwrap()
        };
        let first = write("a.exr");
        for i in 0..4 {
            assert!(first == write(&format!("b{i}.exr")), "write {i} differs");
        }
        assert_eq!(read_image(&dir.join("a.exr")).unwrap().2, pixels);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
