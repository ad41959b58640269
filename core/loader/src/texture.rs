//! Textures and images as a scene file names them: a texture table (Mitsuba 3's `bitmap` and
//! `checkerboard`) into core's [`Texture`], and an image file decoded into core's [`Bitmap`] of
//! linear RGB (the `image` crate is the loader's: core only sees decoded pixels). The
//! conventions are core's ([`foton_core::texture`]).

use foton_core::Rgb;
use foton_core::error::{Error, Result};
use foton_core::props::Properties;
use foton_core::texture::{Bitmap, FilterType, Texture, WrapMode, srgb_to_linear};
use foton_core::value::{Node, Table, Value};
use glam::{Affine2, DVec3, Mat2, Vec2};
use std::path::Path;
use std::sync::Arc;

pub const TEXTURE_TYPES: &[&str] = &[
    "bitmap",
    "checkerboard",
    "constant",
    "mesh_attribute",
    "volume",
];

/// Reads an image (PNG, JPEG, OpenEXR, Radiance HDR, BMP, TGA, PPM/PGM: Mitsuba's formats but
/// PFM; the format is recognised by its content), as linear RGB. 8- and 16-bit images are sRGB-decoded unless `raw`; float
/// images are taken as linear. The error names the file; a texel that is not finite is
/// an error.
pub fn load_bitmap(path: &Path, raw: bool) -> Result<Bitmap> {
    load_bitmap_decoded(path, if raw { Decode::Linear } else { Decode::Srgb })
}

/// How an image's stored values become linear ones (floating-point images are linear
/// whatever this says).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Decode {
    /// The sRGB curve (8- and 16-bit images' usual encoding).
    Srgb,
    /// As stored (`raw`).
    Linear,
    /// A power law: stored value v is linear v^gamma (Mitsuba 0.6's bitmap `gamma`).
    Gamma(f32),
}

/// [`load_bitmap`] with the decoding of its values given.
pub fn load_bitmap_decoded(path: &Path, decode: Decode) -> Result<Bitmap> {
    let is_pfm = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("pfm"));
    let decoded = if is_pfm {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        image::DynamicImage::ImageRgb32F(
            read_pfm(&bytes)
                .map_err(|e| Error::io(path, format!("cannot decode the PFM image: {e}")))?,
        )
    } else {
        image::ImageReader::open(path)
            .map_err(|e| Error::io(path, e))?
            .with_guessed_format()
            .map_err(|e| Error::io(path, e))?
            .decode()
            .map_err(|e| Error::io(path, format!("cannot decode the image: {e}")))?
    };
    let float = matches!(
        decoded,
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
    );
    let decode = if float { Decode::Linear } else { decode };
    let rgb = decoded.to_rgb32f();
    let (width, height) = (rgb.width() as usize, rgb.height() as usize);
    let mut texels = Vec::with_capacity(width * height);
    for (i, p) in rgb.pixels().enumerate() {
        let c = Rgb::from_array(p.0);
        if !c.is_finite() {
            return Err(Error::io(
                path,
                format!(
                    "pixel ({}, {}) is not finite: {c}",
                    i % width.max(1),
                    i / width.max(1)
                ),
            ));
        }
        texels.push(match decode {
            Decode::Linear => c,
            Decode::Srgb => c.map(srgb_to_linear),
            Decode::Gamma(g) => c.map(|v| v.max(0.0).powf(g)),
        });
    }
    Bitmap::new(width, height, texels).ok_or_else(|| Error::io(path, "the image is empty"))
}

/// A portable float map (PFM), which the image crate does not read: a text header (`PF`
/// for RGB or `Pf` for grey, the width and height, then a scale whose sign gives the byte
/// order, negative for little-endian), then 32-bit floats row by row from the bottom. The
/// values are multiplied by the scale's magnitude, as pbrt-v4 and Mitsuba 3 read them.
pub fn read_pfm(bytes: &[u8]) -> std::result::Result<image::Rgb32FImage, String> {
    let mut at = 0;
    let mut word = || -> std::result::Result<String, String> {
        while at < bytes.len() && bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        let start = at;
        while at < bytes.len() && !bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        if start == at {
            return Err("the header ends early".into());
        }
        Ok(String::from_utf8_lossy(&bytes[start..at]).into_owned())
    };
    let channels = match word()?.as_str() {
        "PF" => 3,
        "Pf" => 1,
        other => {
            return Err(format!(
                "expected `PF` or `Pf` at the start, found `{other}`"
            ));
        }
    };
    let size = |w: String| {
        w.parse::<u32>()
            .ok()
            .filter(|n| (1..=1 << 16).contains(n))
            .ok_or_else(|| format!("`{w}` is not an image size (1 to 65536)"))
    };
    let (width, height) = (size(word()?)?, size(word()?)?);
    let w = word()?;
    let scale: f32 = w
        .parse()
        .ok()
        .filter(|s: &f32| s.is_finite())
        .ok_or_else(|| format!("`{w}` is not a scale"))?;
    // One whitespace character separates the header from the data.
    let data = &bytes[(at + 1).min(bytes.len())..];
    let n = width as usize * height as usize * channels;
    if data.len() < 4 * n {
        return Err(format!(
            "{} bytes of pixels where {width} x {height} x {channels} floats need {}",
            data.len(),
            4 * n
        ));
    }
    let value = |i: usize| {
        let b: [u8; 4] = data[4 * i..4 * i + 4].try_into().expect("4 bytes");
        let v = if scale < 0.0 {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        };
        v * scale.abs()
    };
    let (w, h) = (width as usize, height as usize);
    let mut rgb = Vec::with_capacity(3 * w * h);
    for y in 0..h {
        let row = h - 1 - y;
        for x in 0..w {
            let i = (row * w + x) * channels;
            if channels == 3 {
                rgb.extend([value(i), value(i + 1), value(i + 2)]);
            } else {
                rgb.extend([value(i); 3]);
            }
        }
    }
    image::Rgb32FImage::from_raw(width, height, rgb).ok_or_else(|| "the image is empty".into())
}

/// A colour of a texture table: `key` as `[r, g, b]` or one number, `missing` per channel
/// where it is absent or not a number.
pub(crate) fn table_colour(table: &Table, key: &str, missing: f64) -> DVec3 {
    match table.get(key).map(|n| &n.value) {
        Some(Value::Array(a)) if a.len() == 3 => DVec3::new(
            a[0].value.as_f64().unwrap_or(missing),
            a[1].value.as_f64().unwrap_or(missing),
            a[2].value.as_f64().unwrap_or(missing),
        ),
        Some(v) => DVec3::splat(v.as_f64().unwrap_or(missing)),
        None => DVec3::splat(missing),
    }
}

/// Multiplies a texture table's values by `s` (a bitmap's `scale`, a checkerboard's two
/// colours), each new colour written by `node`: the readers' scale textures.
pub(crate) fn scale_texture_table(table: &mut Table, s: DVec3, node: impl Fn(DVec3) -> Node) {
    let keys: &[&str] = match table.get("type") {
        Some(Node {
            value: Value::Str(k),
            ..
        }) if k == "checkerboard" => &["color0", "color1"],
        Some(Node {
            value: Value::Str(k),
            ..
        }) if k == "constant" => &["value"],
        _ => &["scale"],
    };
    for key in keys {
        let scaled = table_colour(table, key, 1.0) * s;
        table.insert(key, node(scaled));
    }
}

/// The images a load has decoded, by file and decoding: a file that many materials' textures
/// name is read once.
pub type Bitmaps = std::collections::HashMap<(std::path::PathBuf, u64), Arc<Bitmap>>;

/// A texture table (`type = "bitmap"`, `"checkerboard"`, `"constant"` or `"mesh_attribute"`
/// and its parameters, see
/// docs/scene-format.md); `filename` is relative to `base_dir`. Every error names the
/// scene file, line and key; an image that cannot be read also names the image file.
pub fn read_texture(t: &Properties<'_>, base_dir: &Path, bitmaps: &mut Bitmaps) -> Result<Texture> {
    let ty = t.string_opt("type")?.ok_or_else(|| {
        t.error(
            "type",
            format!("missing; expected one of: {}", TEXTURE_TYPES.join(", ")),
        )
    })?;
    match ty {
        "bitmap" => {
            let filename = t.string_required("filename")?;
            let raw = t.bool("raw", false)?;
            let decode = match t.f32_opt("gamma")? {
                None if raw => Decode::Linear,
                None => Decode::Srgb,
                Some(_) if raw => {
                    return Err(t.error("gamma", "give `raw` or `gamma`, not both"));
                }
                Some(g) if g > 0.0 && g.is_finite() => Decode::Gamma(g),
                Some(g) => return Err(t.error("gamma", format!("must be positive, found {g}"))),
            };
            let key = match decode {
                Decode::Srgb => 0,
                Decode::Linear => 1,
                Decode::Gamma(g) => 2 + g.to_bits() as u64,
            };
            let filter = match t.choice("filter_type", &["bilinear", "nearest"], "bilinear")? {
                "nearest" => FilterType::Nearest,
                _ => FilterType::Bilinear,
            };
            let wrap = match t.choice("wrap_mode", &["repeat", "mirror", "clamp"], "repeat")? {
                "mirror" => WrapMode::Mirror,
                "clamp" => WrapMode::Clamp,
                _ => WrapMode::Repeat,
            };
            let to_uv = read_to_uv(t)?;
            let scale = match t.node("scale").map(|n| &n.value) {
                None => Rgb::ONE,
                Some(Value::Array(_)) => t.rgb("scale", Rgb::ONE)?,
                Some(_) => Rgb::splat(t.f32_required("scale")?),
            };
            if scale.min_element() < 0.0 {
                return Err(t.error("scale", "must not be negative"));
            }
            let path = base_dir.join(filename);
            let mut bitmap = match bitmaps.get(&(path.clone(), key)) {
                Some(b) => b.clone(),
                None => {
                    let b = Arc::new(
                        load_bitmap_decoded(&path, decode)
                            .map_err(|e| t.error("filename", e.to_string()))?,
                    );
                    bitmaps.insert((path, key), b.clone());
                    b
                }
            };
            if scale != Rgb::ONE {
                let texels = bitmap.texels().iter().map(|c| *c * scale).collect();
                bitmap = Arc::new(
                    Bitmap::new(bitmap.width(), bitmap.height(), texels).expect("same size"),
                );
            }
            Ok(Texture::Bitmap {
                bitmap,
                filter,
                wrap,
                to_uv,
            })
        }
        "constant" => Ok(Texture::Constant(t.vec3_required("value")?)),
        // The scene loader reads a volume's grid (build::common's `texture`).
        "volume" => Err(t.error(
            "type",
            "a volume texture is read where the scene is loaded, not here",
        )),
        "mesh_attribute" => {
            let name = t.string_required("name")?;
            if !(name.starts_with("vertex_") || name.starts_with("face_")) {
                return Err(t.error(
                    "name",
                    format!("{name:?}: a mesh attribute's name starts with `vertex_` or `face_`"),
                ));
            }
            let scale = match t.node("scale").map(|n| &n.value) {
                None => Rgb::ONE,
                Some(Value::Array(_)) => t.rgb("scale", Rgb::ONE)?,
                Some(_) => Rgb::splat(t.f32_required("scale")?),
            };
            Ok(Texture::MeshAttribute {
                name: name.into(),
                scale,
            })
        }
        "checkerboard" => Ok(Texture::Checkerboard {
            // Mitsuba's defaults.
            color0: t.rgb("color0", Rgb::splat(0.4))?,
            color1: t.rgb("color1", Rgb::splat(0.2))?,
            to_uv: read_to_uv(t)?,
        }),
        other => Err(t.error(
            "type",
            format!(
                "unknown texture type {other:?}; expected one of: {}",
                TEXTURE_TYPES.join(", ")
            ),
        )),
    }
}

/// Parameter `name` of `bag` as a colour that may vary: `[r, g, b]` (a constant) or a
/// texture table, `default` when absent. Returns the texture table's bag too, so that the
/// caller can report its unused keys.
pub fn read_texture_param<'a>(
    bag: &Properties<'a>,
    name: &str,
    default: Rgb,
    base_dir: &Path,
    bitmaps: &mut Bitmaps,
) -> Result<(Texture, Option<Properties<'a>>)> {
    let is_table = bag
        .node(name)
        .is_some_and(|n| matches!(n.value, Value::Table(_)));
    if is_table {
        let t = bag.table(name)?.expect("present");
        let texture = read_texture(&t, base_dir, bitmaps)?;
        Ok((texture, Some(t)))
    } else {
        Ok((Texture::Constant(bag.rgb(name, default)?), None))
    }
}

/// `to_uv`: a table with `matrix`, 9 numbers (3 x 3, row-major, last row [0, 0, 1]) or 16 (a
/// 4 x 4 whose third row and column are dropped, as Mitsuba does), or with `scale` (a number
/// or [su, sv]) and `offset` ([ou, ov]): uv' = scale uv + offset. Identity when absent.
fn read_to_uv(t: &Properties<'_>) -> Result<Affine2> {
    let Some(m) = t.table("to_uv")? else {
        return Ok(Affine2::IDENTITY);
    };
    let affine = if m.has("matrix") {
        if let Some(other) = ["scale", "offset"].iter().find(|k| m.has(k)) {
            return Err(m.error(
                other,
                "to_uv is either `matrix` or scale and offset, not both",
            ));
        }
        let n = match m.node("matrix").map(|n| &n.value) {
            Some(Value::Array(items)) if items.len() == 16 => 16,
            _ => 9,
        };
        let v = m.floats_opt("matrix", n)?.expect("present");
        // Rows 0, 1 and the last; columns 0, 1 and the last.
        let (r, c) = if n == 9 { (3, 2) } else { (4, 3) };
        let last = [v[r * (r - 1)], v[r * (r - 1) + 1], v[r * r - 1]];
        if last != [0.0, 0.0, 1.0] {
            return Err(m.error(
                "matrix",
                format!("the last row must be [0, 0, 1] (an affine map of uv), found {last:?}"),
            ));
        }
        Affine2::from_mat2_translation(
            Mat2::from_cols(Vec2::new(v[0], v[r]), Vec2::new(v[1], v[r + 1])),
            Vec2::new(v[c], v[r + c]),
        )
    } else {
        let scale = match m.node("scale").map(|n| &n.value) {
            None => Vec2::ONE,
            Some(Value::Array(_)) => Vec2::from_slice(&m.floats_opt("scale", 2)?.expect("present")),
            Some(_) => Vec2::splat(m.f32_required("scale")?),
        };
        let offset = m
            .floats_opt("offset", 2)?
            .map_or(Vec2::ZERO, |v| Vec2::from_slice(&v));
        Affine2::from_scale_angle_translation(scale, 0.0, offset)
    };
    if let Some(u) = m.unused().first() {
        return Err(m.error(
            u.key.rsplit('.').next().unwrap_or(&u.key),
            "unknown parameter of to_uv; expected matrix, or scale and offset",
        ));
    }
    Ok(affine)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::TomlDocument;
    use foton_core::value::Document;
    use std::path::PathBuf;

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("foton-texture-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Reads the texture written as the TOML table `text` (a `[t]` section).
    fn read(dir: &Path, text: &str) -> Result<Texture> {
        let file = dir.join("scene.toml");
        let doc = Document::parse(text, &file)?;
        let root = Properties::root(&file, &doc.root);
        let t = root.table("t")?.unwrap();
        read_texture(&t, dir, &mut Bitmaps::new())
    }

    fn close(a: Rgb, b: Rgb) -> bool {
        (a - b).abs().max_element() <= 1e-6 * b.abs().max_element().max(1.0)
    }

    /// 3 x 2 sRGB bytes, row 0 first.
    const PIXELS: [[u8; 3]; 6] = [
        [0, 64, 128],
        [255, 10, 200],
        [30, 30, 30],
        [90, 180, 5],
        [128, 128, 128],
        [250, 0, 60],
    ];

    fn write_png(dir: &Path) -> PathBuf {
        let path = dir.join("t.png");
        let img = image::RgbImage::from_raw(3, 2, PIXELS.concat()).unwrap();
        img.save(&path).unwrap();
        path
    }

    fn linear(i: usize) -> Rgb {
        Rgb::from_array(PIXELS[i].map(|b| srgb_to_linear(b as f32 / 255.0)))
    }

    /// A file named by several textures of a load is decoded once and shared; a `scale`
    /// makes its own scaled copy.
    #[test]
    fn a_load_decodes_each_image_once() {
        let dir = temp_dir("shared");
        write_png(&dir);
        let file = dir.join("scene.toml");
        let text = "[a]\ntype = \"bitmap\"\nfilename = \"t.png\"\n[b]\ntype = \"bitmap\"\nfilename = \"t.png\"\n[c]\ntype = \"bitmap\"\nfilename = \"t.png\"\nscale = 2.0\n";
        let doc = Document::parse(text, &file).unwrap();
        let root = Properties::root(&file, &doc.root);
        let mut bitmaps = Bitmaps::new();
        let mut read =
            |k: &str| match read_texture(&root.table(k).unwrap().unwrap(), &dir, &mut bitmaps)
                .unwrap()
            {
                Texture::Bitmap { bitmap, .. } => bitmap,
                other => panic!("{other:?}"),
            };
        let (a, b, c) = (read("a"), read("b"), read("c"));
        assert!(Arc::ptr_eq(&a, &b));
        assert!(!Arc::ptr_eq(&a, &c));
        assert_eq!(c.texel(0, 0), a.texel(0, 0) * 2.0);
        assert_eq!(bitmaps.len(), 1);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn bitmap_lookups_read_texel_centres_interpolate_between_them_and_repeat() {
        let dir = temp_dir("png");
        write_png(&dir);
        let t = read(&dir, "[t]\ntype = \"bitmap\"\nfilename = \"t.png\"\n").unwrap();
        let centre = |i: usize, j: usize| Vec2::new((i as f32 + 0.5) / 3.0, (j as f32 + 0.5) / 2.0);
        for j in 0..2 {
            for i in 0..3 {
                let want = linear(j * 3 + i);
                assert!(close(t.eval(centre(i, j).into()), want), "texel ({i}, {j})");
                // Repeat: whole periods further, either way.
                let far = centre(i, j) + Vec2::new(2.0, -3.0);
                assert!(
                    close(t.eval(far.into()), want),
                    "texel ({i}, {j}) + (2, -3)"
                );
            }
        }
        // Half-way between texel centres: the average of the two (four) texels.
        let mid = t.eval(Vec2::new(1.0 / 3.0, 0.25).into());
        assert!(close(mid, 0.5 * (linear(0) + linear(1))));
        let mid4 = t.eval(Vec2::new(1.0 / 3.0, 0.5).into());
        assert!(close(
            mid4,
            0.25 * (linear(0) + linear(1) + linear(3) + linear(4))
        ));
        // uv = (0, 0), the top-left corner, averages the four corner texels (repeat).
        let corner = t.eval(Vec2::ZERO.into());
        assert!(close(
            corner,
            0.25 * (linear(0) + linear(2) + linear(3) + linear(5))
        ));
        // Nearest: the texel containing the point.
        let n = read(
            &dir,
            "[t]\ntype = \"bitmap\"\nfilename = \"t.png\"\nfilter_type = \"nearest\"\n",
        )
        .unwrap();
        assert_eq!(n.eval(Vec2::new(0.34, 0.49).into()), linear(1));
        assert_eq!(n.eval(Vec2::new(0.99, 0.51).into()), linear(5));
        // raw: the bytes over 255, not decoded.
        let raw = read(
            &dir,
            "[t]\ntype = \"bitmap\"\nfilename = \"t.png\"\nraw = true\n",
        )
        .unwrap();
        let want = Rgb::from_array(PIXELS[4].map(|b| b as f32 / 255.0));
        assert!(close(raw.eval(centre(1, 1).into()), want));
        assert!(close(t.mean(), (0..6).map(linear).sum::<Rgb>() / 6.0));
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn wrap_modes_and_to_uv() {
        let dir = temp_dir("wrap");
        write_png(&dir);
        let with = |extra: &str| {
            let head = "[t]\ntype = \"bitmap\"\nfilename = \"t.png\"\nfilter_type = \"nearest\"";
            read(&dir, &format!("{head}\n{extra}\n")).unwrap()
        };
        let clamp = with("wrap_mode = \"clamp\"");
        assert_eq!(clamp.eval(Vec2::new(-5.0, 0.2).into()), linear(0));
        assert_eq!(clamp.eval(Vec2::new(7.0, 9.0).into()), linear(5));
        let mirror = with("wrap_mode = \"mirror\"");
        // Just past the right edge: the last column again, then going back.
        assert_eq!(mirror.eval(Vec2::new(1.1, 0.2).into()), linear(2));
        assert_eq!(mirror.eval(Vec2::new(1.5, 0.2).into()), linear(1));
        assert_eq!(mirror.eval(Vec2::new(-0.1, 0.2).into()), linear(0));
        assert_eq!(mirror.eval(Vec2::new(0.2, -0.1).into()), linear(0));
        assert_eq!(mirror.eval(Vec2::new(0.2, 1.2).into()), linear(3));
        // to_uv scales then offsets: uv' = 2 uv + (0.5, 0).
        let scaled = with("to_uv = { scale = 2.0, offset = [0.5, 0.0] }");
        assert_eq!(scaled.eval(Vec2::new(0.1, 0.1).into()), linear(2));
        let m9 = with("to_uv = { matrix = [2, 0, 0.5, 0, 2, 0, 0, 0, 1] }");
        let m16 = with("to_uv = { matrix = [2, 0, 0, 0.5, 0, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] }");
        for uv in [
            Vec2::new(0.1, 0.1),
            Vec2::new(0.3, 0.7),
            Vec2::new(-0.4, 0.2),
        ] {
            assert_eq!(m9.eval(uv.into()), scaled.eval(uv.into()));
            assert_eq!(m16.eval(uv.into()), scaled.eval(uv.into()));
        }
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn float_images_are_linear_grey_is_copied_and_alpha_dropped() {
        let dir = temp_dir("formats");
        let values = [
            0.25f32, 3.5, 0.0, 1e-3, 7.0, 0.5, 2.0, 1.0, 0.125, 0.75, 0.0, 12.0,
        ];
        image::Rgb32FImage::from_raw(2, 2, values.to_vec())
            .unwrap()
            .save(dir.join("t.exr"))
            .unwrap();
        let exr = load_bitmap(&dir.join("t.exr"), false).unwrap();
        for i in 0..4 {
            assert_eq!(exr.texels()[i], Rgb::from_slice(&values[3 * i..3 * i + 3]));
        }
        let hdr = dir.join("t.hdr");
        image::Rgb32FImage::from_raw(2, 2, values.to_vec())
            .unwrap()
            .save(&hdr)
            .unwrap();
        let h = load_bitmap(&hdr, false).unwrap();
        for i in 0..4 {
            let want = Rgb::from_slice(&values[3 * i..3 * i + 3]);
            // RGBE keeps 8 bits of mantissa for the largest channel.
            assert!((h.texels()[i] - want).abs().max_element() <= want.max_element() / 100.0);
        }
        image::GrayImage::from_raw(2, 1, vec![100, 200])
            .unwrap()
            .save(dir.join("g.png"))
            .unwrap();
        let g = load_bitmap(&dir.join("g.png"), false).unwrap();
        assert!(close(
            g.texels()[1],
            Rgb::splat(srgb_to_linear(200.0 / 255.0))
        ));
        image::RgbaImage::from_raw(1, 1, vec![200, 100, 50, 128])
            .unwrap()
            .save(dir.join("a.png"))
            .unwrap();
        let a = load_bitmap(&dir.join("a.png"), true).unwrap();
        assert!(close(a.texels()[0], Rgb::new(200.0, 100.0, 50.0) / 255.0));
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn checkerboard_quadrants_are_mitsubas() {
        let dir = temp_dir("checker");
        let t = read(
            &dir,
            "[t]\ntype = \"checkerboard\"\ncolor0 = [1, 0, 0]\ncolor1 = [0, 0, 1]\n",
        )
        .unwrap();
        let (c0, c1) = (Rgb::X, Rgb::Z);
        assert_eq!(t.eval(Vec2::new(0.25, 0.25).into()), c0);
        assert_eq!(t.eval(Vec2::new(0.75, 0.75).into()), c0);
        assert_eq!(t.eval(Vec2::new(0.75, 0.25).into()), c1);
        assert_eq!(t.eval(Vec2::new(0.25, 0.75).into()), c1);
        // 1/2 itself belongs to the low half; negative uv repeats.
        assert_eq!(t.eval(Vec2::new(0.5, 0.5).into()), c0);
        assert_eq!(t.eval(Vec2::new(-0.25, 0.25).into()), c1);
        assert_eq!(t.mean(), Rgb::new(0.5, 0.0, 0.5));
        let d = read(&dir, "[t]\ntype = \"checkerboard\"\n").unwrap();
        assert_eq!(d.eval(Vec2::splat(0.1).into()), Rgb::splat(0.4));
        assert_eq!(d.eval(Vec2::new(0.6, 0.1).into()), Rgb::splat(0.2));
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn bad_textures_are_errors_naming_the_file() {
        let dir = temp_dir("errors");
        std::fs::write(dir.join("junk.png"), "not an image").unwrap();
        let cases = [
            ("filename = \"missing.png\"", "missing.png"),
            ("filename = \"junk.png\"", "junk.png: cannot decode"),
            ("", "`t.filename`: missing"),
            (
                "filename = \"junk.png\"\nfilter_type = \"cubic\"",
                "unknown value \"cubic\"",
            ),
            (
                "filename = \"junk.png\"\nwrap_mode = \"wrap\"",
                "expected one of: repeat, mirror, clamp",
            ),
            (
                "filename = \"junk.png\"\nto_uv = { matrix = [1, 0, 0, 0, 1, 0, 1, 0, 1] }",
                "last row",
            ),
            (
                "filename = \"junk.png\"\nto_uv = { translate = [1, 0] }",
                "`t.to_uv.translate`",
            ),
        ];
        for (extra, want) in cases {
            let e = read(&dir, &format!("[t]\ntype = \"bitmap\"\n{extra}\n"))
                .unwrap_err()
                .to_string();
            assert!(e.contains(want), "{extra}: {e}");
            assert!(e.contains("scene.toml:"), "{extra}: {e}");
        }
        let e = read(&dir, "[t]\ntype = \"marble\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown texture type \"marble\""), "{e}");
        let _ = std::fs::remove_dir_all(dir);
    }

    /// PFM: RGB and grey, both byte orders, rows from the bottom, the scale's magnitude
    /// applied; short or malformed files are errors.
    #[test]
    fn pfm_images_read_as_pbrt_and_mitsuba_read_them() {
        let file = |head: &str, values: &[f32], little: bool| {
            let mut b = head.as_bytes().to_vec();
            for v in values {
                b.extend(if little {
                    v.to_le_bytes()
                } else {
                    v.to_be_bytes()
                });
            }
            b
        };
        // 2 x 2 RGB, little-endian, scale 2: the bottom row is written first.
        let values = [
            1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0,
        ];
        let img = read_pfm(&file("PF\n2 2\n-2.0\n", &values, true)).unwrap();
        assert_eq!(img.get_pixel(0, 0).0, [14.0, 16.0, 18.0]);
        assert_eq!(img.get_pixel(1, 1).0, [8.0, 10.0, 12.0]);
        // Grey, big-endian, scale 1.
        let img = read_pfm(&file("Pf 2 1 1.0 ", &[0.5, 0.25], false)).unwrap();
        assert_eq!(img.get_pixel(1, 0).0, [0.25; 3]);
        assert!(read_pfm(&file("PF\n2 2\n-1\n", &values[..6], true)).is_err());
        assert!(read_pfm(b"P6\n2 2\n255\n").is_err());
        assert!(read_pfm(b"PF\n2").is_err());
    }
}
