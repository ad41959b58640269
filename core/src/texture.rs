//! Textures: spatially varying colours looked up by surface (u, v), as Mitsuba 3's `bitmap` and
//! `checkerboard` textures, and the [`Bitmap`] image they and the environment map
//! ([`crate::envmap`]) share, with its one bilinear lookup.
//!
//! Mitsuba's conventions, checked against Mitsuba 3.9.1 itself:
//! - texel (i, j) is column i of row j, row 0 the image's top row (the file's first row), and
//!   uv = (0, 0) is the top-left corner of the image: the texture does not flip v (Mitsuba's
//!   OBJ reader flips v on load instead, `flip_tex_coords`, default true);
//! - texel centres sit at uv = ((i + 1/2) / width, (j + 1/2) / height): a bilinear lookup at
//!   uv reads texel coordinates (u width - 1/2, v height - 1/2), a nearest one the texel
//!   (floor(u width), floor(v height));
//! - `to_uv` maps the surface's uv before the lookup (uv' = A uv + b);
//! - 8- and 16-bit images (PNG, JPEG) are sRGB-encoded and decoded to linear unless `raw`;
//!   float images (OpenEXR, Radiance HDR) are linear; grey is copied to the three channels and
//!   alpha is dropped (not multiplied in);
//! - the checkerboard is `color0` where frac(u) and frac(v) lie on the same side of 1/2 (both
//!   <= 1/2 or both > 1/2), `color1` elsewhere.

use crate::Rgb;
use crate::error::{Error, Result};
use crate::props::Properties;
use glam::{Affine2, Mat2, Vec2};
use std::path::Path;
use std::sync::Arc;

/// How a lookup between texels combines them (Mitsuba's `filter_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilterType {
    /// Bilinear interpolation of the four nearest texel centres.
    Bilinear,
    /// The texel the point falls in.
    Nearest,
}

/// What a lookup outside [0, 1] reads (Mitsuba's `wrap_mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WrapMode {
    /// The image tiles the plane.
    Repeat,
    /// The image tiles the plane, every other copy mirrored (edges repeat their texel).
    Mirror,
    /// The edge texels extend outwards.
    Clamp,
}

impl WrapMode {
    /// The texel index that index `i` reads along an axis of `n` texels (drjit's `tex_wrap`).
    #[inline]
    fn wrap(self, i: i64, n: usize) -> usize {
        let n = n as i64;
        (match self {
            WrapMode::Clamp => i.clamp(0, n - 1),
            WrapMode::Repeat => i.rem_euclid(n),
            WrapMode::Mirror => {
                let p = i.rem_euclid(2 * n);
                if p < n { p } else { 2 * n - 1 - p }
            }
        }) as usize
    }
}

/// Mitsuba's sRGB decoding curve (IEC 61966-2-1): the linear value of an encoded one in [0, 1].
#[inline]
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// Luminance of linear sRGB (Rec. 709 primaries), Mitsuba's `luminance`.
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z
}

/// A linear RGB image, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Bitmap {
    width: usize,
    height: usize,
    texels: Vec<Rgb>,
}

impl Bitmap {
    /// A `width` x `height` image from its texels, row by row from the top. None if the sizes
    /// disagree or the image is empty.
    pub fn new(width: usize, height: usize, texels: Vec<Rgb>) -> Option<Bitmap> {
        (width > 0 && height > 0 && texels.len() == width * height).then_some(Bitmap {
            width,
            height,
            texels,
        })
    }

    /// Reads an image (PNG, JPEG, OpenEXR, Radiance HDR; the format is recognised by its
    /// content), as linear RGB. 8- and 16-bit images are sRGB-decoded unless `raw`; float
    /// images are taken as linear. The error names the file; a texel that is not finite is
    /// an error.
    pub fn load(path: &Path, raw: bool) -> Result<Bitmap> {
        let decoded = image::ImageReader::open(path)
            .map_err(|e| Error::io(path, e))?
            .with_guessed_format()
            .map_err(|e| Error::io(path, e))?
            .decode()
            .map_err(|e| Error::io(path, format!("cannot decode the image: {e}")))?;
        let linear = raw
            || matches!(
                decoded,
                image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
            );
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
            texels.push(if linear { c } else { c.map(srgb_to_linear) });
        }
        Bitmap::new(width, height, texels).ok_or_else(|| Error::io(path, "the image is empty"))
    }

    pub fn width(&self) -> usize {
        self.width
    }
    pub fn height(&self) -> usize {
        self.height
    }
    pub fn texels(&self) -> &[Rgb] {
        &self.texels
    }
    /// Texel (x, y), x the column, y the row from the top.
    #[inline]
    pub fn texel(&self, x: usize, y: usize) -> Rgb {
        self.texels[y * self.width + x]
    }

    /// Grows the image to at least `width` x `height` by repeating its last column and row
    /// (Mitsuba's `Bitmap::pad_to`, for lookups that need two texels per axis).
    pub fn pad_to(&self, width: usize, height: usize) -> Bitmap {
        let (w, h) = (self.width.max(width), self.height.max(height));
        let mut texels = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                texels.push(self.texel(x.min(self.width - 1), y.min(self.height - 1)));
            }
        }
        Bitmap {
            width: w,
            height: h,
            texels,
        }
    }

    /// Bilinear interpolation at continuous texel coordinates (x, y), texel (i, j)'s centre
    /// at (i, j), indices outside the image wrapped per axis: the one lookup of the textures
    /// and the environment map.
    #[inline]
    pub fn bilinear(&self, x: f32, y: f32, wrap: [WrapMode; 2]) -> Rgb {
        let (x, y) = (finite_or_zero(x), finite_or_zero(y));
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let (xa, xb) = (
            wrap[0].wrap(x0, self.width),
            wrap[0].wrap(x0 + 1, self.width),
        );
        let (ya, yb) = (
            wrap[1].wrap(y0, self.height),
            wrap[1].wrap(y0 + 1, self.height),
        );
        let top = self.texel(xa, ya) * (1.0 - fx) + self.texel(xb, ya) * fx;
        let bottom = self.texel(xa, yb) * (1.0 - fx) + self.texel(xb, yb) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The texel containing the continuous texel coordinates (x, y) (texel (i, j) covers
    /// [i, i + 1) x [j, j + 1)), wrapped per axis.
    #[inline]
    pub fn nearest(&self, x: f32, y: f32, wrap: [WrapMode; 2]) -> Rgb {
        let (x, y) = (finite_or_zero(x), finite_or_zero(y));
        self.texel(
            wrap[0].wrap(x.floor() as i64, self.width),
            wrap[1].wrap(y.floor() as i64, self.height),
        )
    }

    /// Mean of the texels.
    pub fn mean(&self) -> Rgb {
        let sum = self
            .texels
            .iter()
            .fold(glam::DVec3::ZERO, |s, c| s + c.as_dvec3());
        (sum / self.texels.len() as f64).as_vec3()
    }

    /// Per-channel maximum of the texels (a bound of every lookup: interpolation only
    /// averages them).
    pub fn max(&self) -> Rgb {
        self.texels.iter().fold(Rgb::ZERO, |m, &c| m.max(c))
    }
}

/// Huge or non-finite coordinates (a degenerate uv) read texel 0 instead of overflowing.
#[inline]
fn finite_or_zero(x: f32) -> f32 {
    if x.abs() < 1e15 { x } else { 0.0 }
}

/// A colour that varies over a surface with its (u, v).
#[derive(Clone, Debug)]
pub enum Texture {
    Constant(Rgb),
    /// An image (Mitsuba's `bitmap`).
    Bitmap {
        bitmap: Arc<Bitmap>,
        filter: FilterType,
        wrap: WrapMode,
        /// Applied to the surface's uv before the lookup.
        to_uv: Affine2,
    },
    /// Two colours in a 2 x 2 checkerboard over each unit square of uv (Mitsuba's
    /// `checkerboard`).
    Checkerboard {
        color0: Rgb,
        color1: Rgb,
        to_uv: Affine2,
    },
}

pub const TEXTURE_TYPES: &[&str] = &["bitmap", "checkerboard"];

impl Texture {
    /// The colour at surface coordinates `uv`.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bitmap {
                bitmap,
                filter,
                wrap,
                to_uv,
            } => {
                let uv = to_uv.transform_point2(uv);
                let (w, h) = (bitmap.width() as f32, bitmap.height() as f32);
                match filter {
                    FilterType::Bilinear => {
                        bitmap.bilinear(uv.x * w - 0.5, uv.y * h - 0.5, [*wrap; 2])
                    }
                    FilterType::Nearest => bitmap.nearest(uv.x * w, uv.y * h, [*wrap; 2]),
                }
            }
            Texture::Checkerboard {
                color0,
                color1,
                to_uv,
            } => {
                let uv = to_uv.transform_point2(uv);
                let high = (uv - uv.floor()).cmpgt(Vec2::splat(0.5));
                if high.test(0) == high.test(1) {
                    *color0
                } else {
                    *color1
                }
            }
        }
    }

    /// The mean colour over the unit square of uv (of the image, of the two colours).
    pub fn mean(&self) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bitmap { bitmap, .. } => bitmap.mean(),
            Texture::Checkerboard { color0, color1, .. } => 0.5 * (*color0 + *color1),
        }
    }

    /// A per-channel bound of every value `eval` returns (for checking that a reflectance
    /// stays within 1, or bounding Russian roulette).
    pub fn max(&self) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bitmap { bitmap, .. } => bitmap.max(),
            Texture::Checkerboard { color0, color1, .. } => color0.max(*color1),
        }
    }

    /// Whether `eval` is the same everywhere.
    pub fn is_constant(&self) -> bool {
        matches!(self, Texture::Constant(_))
    }

    /// A texture table (`type = "bitmap"` or `"checkerboard"` and its parameters, see
    /// docs/scene-format.md); `filename` is relative to `base_dir`. Every error names the
    /// scene file, line and key; an image that cannot be read also names the image file.
    pub fn read(t: &Properties<'_>, base_dir: &Path) -> Result<Texture> {
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
                let bitmap = Bitmap::load(&base_dir.join(filename), raw)
                    .map_err(|e| t.error("filename", e.to_string()))?;
                Ok(Texture::Bitmap {
                    bitmap: Arc::new(bitmap),
                    filter,
                    wrap,
                    to_uv,
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
    pub fn read_param<'a>(
        bag: &Properties<'a>,
        name: &str,
        default: Rgb,
        base_dir: &Path,
    ) -> Result<(Texture, Option<Properties<'a>>)> {
        let is_table = bag
            .node(name)
            .is_some_and(|n| matches!(n.value, crate::value::Value::Table(_)));
        if is_table {
            let t = bag.table(name)?.expect("present");
            let texture = Texture::read(&t, base_dir)?;
            Ok((texture, Some(t)))
        } else {
            Ok((Texture::Constant(bag.rgb(name, default)?), None))
        }
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
            Some(crate::value::Value::Array(items)) if items.len() == 16 => 16,
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
            Some(crate::value::Value::Array(_)) => {
                Vec2::from_slice(&m.floats_opt("scale", 2)?.expect("present"))
            }
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
    use crate::value::Document;
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
        Texture::read(&t, dir)
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

    #[test]
    fn bitmap_lookups_read_texel_centres_interpolate_between_them_and_repeat() {
        let dir = temp_dir("png");
        write_png(&dir);
        let t = read(&dir, "[t]\ntype = \"bitmap\"\nfilename = \"t.png\"\n").unwrap();
        let centre = |i: usize, j: usize| Vec2::new((i as f32 + 0.5) / 3.0, (j as f32 + 0.5) / 2.0);
        for j in 0..2 {
            for i in 0..3 {
                let want = linear(j * 3 + i);
                assert!(close(t.eval(centre(i, j)), want), "texel ({i}, {j})");
                // Repeat: whole periods further, either way.
                let far = centre(i, j) + Vec2::new(2.0, -3.0);
                assert!(close(t.eval(far), want), "texel ({i}, {j}) + (2, -3)");
            }
        }
        // Half-way between texel centres: the average of the two (four) texels.
        let mid = t.eval(Vec2::new(1.0 / 3.0, 0.25));
        assert!(close(mid, 0.5 * (linear(0) + linear(1))));
        let mid4 = t.eval(Vec2::new(1.0 / 3.0, 0.5));
        assert!(close(
            mid4,
            0.25 * (linear(0) + linear(1) + linear(3) + linear(4))
        ));
        // uv = (0, 0), the top-left corner, averages the four corner texels (repeat).
        let corner = t.eval(Vec2::ZERO);
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
        assert_eq!(n.eval(Vec2::new(0.34, 0.49)), linear(1));
        assert_eq!(n.eval(Vec2::new(0.99, 0.51)), linear(5));
        // raw: the bytes over 255, not decoded.
        let raw = read(
            &dir,
            "[t]\ntype = \"bitmap\"\nfilename = \"t.png\"\nraw = true\n",
        )
        .unwrap();
        let want = Rgb::from_array(PIXELS[4].map(|b| b as f32 / 255.0));
        assert!(close(raw.eval(centre(1, 1)), want));
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
        assert_eq!(clamp.eval(Vec2::new(-5.0, 0.2)), linear(0));
        assert_eq!(clamp.eval(Vec2::new(7.0, 9.0)), linear(5));
        let mirror = with("wrap_mode = \"mirror\"");
        // Just past the right edge: the last column again, then going back.
        assert_eq!(mirror.eval(Vec2::new(1.1, 0.2)), linear(2));
        assert_eq!(mirror.eval(Vec2::new(1.5, 0.2)), linear(1));
        assert_eq!(mirror.eval(Vec2::new(-0.1, 0.2)), linear(0));
        assert_eq!(mirror.eval(Vec2::new(0.2, -0.1)), linear(0));
        assert_eq!(mirror.eval(Vec2::new(0.2, 1.2)), linear(3));
        // to_uv scales then offsets: uv' = 2 uv + (0.5, 0).
        let scaled = with("to_uv = { scale = 2.0, offset = [0.5, 0.0] }");
        assert_eq!(scaled.eval(Vec2::new(0.1, 0.1)), linear(2));
        let m9 = with("to_uv = { matrix = [2, 0, 0.5, 0, 2, 0, 0, 0, 1] }");
        let m16 = with("to_uv = { matrix = [2, 0, 0, 0.5, 0, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] }");
        for uv in [
            Vec2::new(0.1, 0.1),
            Vec2::new(0.3, 0.7),
            Vec2::new(-0.4, 0.2),
        ] {
            assert_eq!(m9.eval(uv), scaled.eval(uv));
            assert_eq!(m16.eval(uv), scaled.eval(uv));
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
        let exr = Bitmap::load(&dir.join("t.exr"), false).unwrap();
        for i in 0..4 {
            assert_eq!(exr.texels()[i], Rgb::from_slice(&values[3 * i..3 * i + 3]));
        }
        let hdr = dir.join("t.hdr");
        image::Rgb32FImage::from_raw(2, 2, values.to_vec())
            .unwrap()
            .save(&hdr)
            .unwrap();
        let h = Bitmap::load(&hdr, false).unwrap();
        for i in 0..4 {
            let want = Rgb::from_slice(&values[3 * i..3 * i + 3]);
            // RGBE keeps 8 bits of mantissa for the largest channel.
            assert!((h.texels()[i] - want).abs().max_element() <= want.max_element() / 100.0);
        }
        image::GrayImage::from_raw(2, 1, vec![100, 200])
            .unwrap()
            .save(dir.join("g.png"))
            .unwrap();
        let g = Bitmap::load(&dir.join("g.png"), false).unwrap();
        assert!(close(
            g.texels()[1],
            Rgb::splat(srgb_to_linear(200.0 / 255.0))
        ));
        image::RgbaImage::from_raw(1, 1, vec![200, 100, 50, 128])
            .unwrap()
            .save(dir.join("a.png"))
            .unwrap();
        let a = Bitmap::load(&dir.join("a.png"), true).unwrap();
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
        assert_eq!(t.eval(Vec2::new(0.25, 0.25)), c0);
        assert_eq!(t.eval(Vec2::new(0.75, 0.75)), c0);
        assert_eq!(t.eval(Vec2::new(0.75, 0.25)), c1);
        assert_eq!(t.eval(Vec2::new(0.25, 0.75)), c1);
        // 1/2 itself belongs to the low half; negative uv repeats.
        assert_eq!(t.eval(Vec2::new(0.5, 0.5)), c0);
        assert_eq!(t.eval(Vec2::new(-0.25, 0.25)), c1);
        assert_eq!(t.mean(), Rgb::new(0.5, 0.0, 0.5));
        let d = read(&dir, "[t]\ntype = \"checkerboard\"\n").unwrap();
        assert_eq!(d.eval(Vec2::splat(0.1)), Rgb::splat(0.4));
        assert_eq!(d.eval(Vec2::new(0.6, 0.1)), Rgb::splat(0.2));
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
}
