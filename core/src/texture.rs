//! Textures: spatially varying colours looked up by surface (u, v), as Mitsuba 3's `bitmap` and
//! `checkerboard` textures, or read from the mesh (Mitsuba 3's `mesh_attribute`), and the
//! [`Bitmap`] image they and the environment map ([`crate::envmap`]) share, with its one
//! bilinear lookup.
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
use crate::medium::grid::Grid;
use glam::{Affine2, Vec2, Vec3};
use std::sync::Arc;

/// Where a texture is looked up (pbrt-v4's `TextureEvalContext`): the surface's texture
/// coordinates, its point in the scene and, on a mesh that carries one, the value there of the
/// mesh attribute its material's textures read (interpolated between the vertices of a vertex
/// attribute).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TextureEvalContext {
    pub uv: Vec2,
    /// The point in the scene (world space), which a volume texture reads.
    pub p: Vec3,
    /// The mesh attribute's value; zero where the surface has none.
    pub attribute: Rgb,
}

impl From<Vec2> for TextureEvalContext {
    #[inline(always)]
    fn from(uv: Vec2) -> TextureEvalContext {
        TextureEvalContext {
            uv,
            ..TextureEvalContext::default()
        }
    }
}

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
    pub(crate) fn wrap(self, i: i64, n: usize) -> usize {
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

/// A colour read as a number, as Mitsuba's `eval_1` reads a texture: a grey's value exactly,
/// another colour's luminance (alpha, roughness).
#[inline]
pub fn scalar(c: Rgb) -> f32 {
    if c.x == c.y && c.y == c.z {
        c.x
    } else {
        luminance(c)
    }
}

/// Luminance of linear sRGB (Rec. 709 primaries), Mitsuba's `luminance`.
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z
}

/// The texels a bilinear lookup blends: columns `xa`, `xb`, rows `ya`, `yb`, weights of the
/// second ones `fx`, `fy`.
struct Cell {
    xa: usize,
    xb: usize,
    ya: usize,
    yb: usize,
    fx: f32,
    fy: f32,
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

    /// The four texels around continuous texel coordinates (x, y) (texel (i, j)'s centre at
    /// (i, j)), wrapped per axis, and the position between them.
    #[inline]
    fn cell(&self, x: f32, y: f32, wrap: [WrapMode; 2]) -> Cell {
        let (x, y) = (finite_or_zero(x), finite_or_zero(y));
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        Cell {
            xa: wrap[0].wrap(x0, self.width),
            xb: wrap[0].wrap(x0 + 1, self.width),
            ya: wrap[1].wrap(y0, self.height),
            yb: wrap[1].wrap(y0 + 1, self.height),
            fx,
            fy,
        }
    }

    /// Bilinear interpolation at continuous texel coordinates (x, y), texel (i, j)'s centre
    /// at (i, j), indices outside the image wrapped per axis: the one lookup of the textures
    /// and the environment map.
    #[inline]
    pub fn bilinear(&self, x: f32, y: f32, wrap: [WrapMode; 2]) -> Rgb {
        let Cell {
            xa,
            xb,
            ya,
            yb,
            fx,
            fy,
        } = self.cell(x, y, wrap);
        let top = self.texel(xa, ya) * (1.0 - fx) + self.texel(xb, ya) * fx;
        let bottom = self.texel(xa, yb) * (1.0 - fx) + self.texel(xb, yb) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The gradient (d/dx, d/dy) of [`Bitmap::bilinear`]'s value read as a number
    /// ([`scalar`]) at (x, y): the exact derivative of the interpolation inside the cell of
    /// four texels that (x, y) falls in (Mitsuba 3's `eval_1_grad`).
    #[inline]
    pub fn bilinear_gradient(&self, x: f32, y: f32, wrap: [WrapMode; 2]) -> Vec2 {
        let Cell {
            xa,
            xb,
            ya,
            yb,
            fx,
            fy,
        } = self.cell(x, y, wrap);
        let f = |x, y| scalar(self.texel(x, y));
        let (f00, f10, f01, f11) = (f(xa, ya), f(xb, ya), f(xa, yb), f(xb, yb));
        Vec2::new(
            (1.0 - fy) * (f10 - f00) + fy * (f11 - f01),
            (1.0 - fx) * (f01 - f00) + fx * (f11 - f10),
        )
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
    /// A mesh's attribute (Mitsuba 3's `mesh_attribute`): `name` (`vertex_...` or `face_...`)
    /// names it, and the shapes that use the texture's material carry it to the surface
    /// ([`TextureEvalContext::attribute`]), scaled here by `scale`.
    MeshAttribute {
        name: Arc<str>,
        scale: Rgb,
    },
    /// A volume grid looked up at the surface's point in the scene (Mitsuba 3's `volume`
    /// texture): trilinear, as a medium's grids.
    Volume(Arc<Grid>),
}

impl Texture {
    /// The colour at `ctx` (its texture coordinates, or its mesh attribute).
    #[inline]
    pub fn eval(&self, ctx: TextureEvalContext) -> Rgb {
        let uv = ctx.uv;
        match self {
            Texture::Constant(c) => *c,
            Texture::MeshAttribute { scale, .. } => ctx.attribute * *scale,
            Texture::Volume(grid) => grid.lookup(ctx.p),
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

    /// The gradient in uv of the texture read as a number ([`scalar`]), as Mitsuba 3's
    /// `eval_1_grad` gives it for its bump maps: a bilinear bitmap's exact derivative (through
    /// its `to_uv`), zero for nearest lookups, constants and checkerboards (piecewise
    /// constant: zero almost everywhere).
    pub fn gradient(&self, uv: Vec2) -> Vec2 {
        match self {
            Texture::Bitmap {
                bitmap,
                filter: FilterType::Bilinear,
                wrap,
                to_uv,
            } => {
                let st = to_uv.transform_point2(uv);
                let (w, h) = (bitmap.width() as f32, bitmap.height() as f32);
                let g = bitmap.bilinear_gradient(st.x * w - 0.5, st.y * h - 0.5, [*wrap; 2]);
                // d f / d uv = J^T (w df/dx, h df/dy), J the linear part of `to_uv`.
                to_uv.matrix2.transpose() * (g * Vec2::new(w, h))
            }
            _ => Vec2::ZERO,
        }
    }

    /// [`Texture::eval`], a constant's colour read without the call: `eval` is too large to
    /// be inlined, and most colours of most scenes are constants (a call per colour per hit
    /// cost about 1% of the path tracer's instructions on the Cornell box). Materials look
    /// their textures up with this.
    #[inline(always)]
    pub fn at(&self, ctx: TextureEvalContext) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            _ => self.eval(ctx),
        }
    }

    /// The name of the mesh attribute the texture reads, if it is a `MeshAttribute`.
    pub fn mesh_attribute(&self) -> Option<&str> {
        match self {
            Texture::MeshAttribute { name, .. } => Some(name),
            _ => None,
        }
    }

    /// The mean colour over the unit square of uv (of the image, of the two colours; a volume's
    /// over its samples). A mesh attribute's is not known to the texture: taken as mid-grey
    /// (times its scale).
    pub fn mean(&self) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::MeshAttribute { scale, .. } => 0.5 * *scale,
            Texture::Volume(grid) => grid.mean(),
            Texture::Bitmap { bitmap, .. } => bitmap.mean(),
            Texture::Checkerboard { color0, color1, .. } => 0.5 * (*color0 + *color1),
        }
    }

    /// A per-channel bound of every value `eval` returns (for checking that a reflectance
    /// stays within 1, or bounding Russian roulette).
    /// A mesh attribute's is taken as its scale (a colour in [0, 1]), since the texture does
    /// not know the meshes that carry it.
    pub fn max(&self) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::MeshAttribute { scale, .. } => *scale,
            Texture::Volume(grid) => Rgb::splat(grid.max()),
            Texture::Bitmap { bitmap, .. } => bitmap.max(),
            Texture::Checkerboard { color0, color1, .. } => color0.max(*color1),
        }
    }

    /// Whether `eval` is the same everywhere.
    pub fn is_constant(&self) -> bool {
        matches!(self, Texture::Constant(_))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gradient is the derivative of the lookup it belongs to: central differences of
    /// `eval` (read as a number) agree with it inside the cells of four texels, through a
    /// rotating, stretching `to_uv` on a non-square image.
    #[test]
    fn a_bilinear_bitmaps_gradient_is_the_derivative_of_its_lookup() {
        let (w, h) = (5usize, 3usize);
        let texels = (0..w * h)
            .map(|i| {
                let x = (i as f32 * 0.618_034).fract();
                Rgb::new(x, (x * 7.0).fract(), 0.3)
            })
            .collect();
        let texture = Texture::Bitmap {
            bitmap: Arc::new(Bitmap::new(w, h, texels).unwrap()),
            filter: FilterType::Bilinear,
            wrap: WrapMode::Repeat,
            to_uv: Affine2::from_scale_angle_translation(
                Vec2::new(1.7, 0.6),
                0.4,
                Vec2::new(0.1, -0.2),
            ),
        };
        let cell = |uv: Vec2| {
            let Texture::Bitmap { to_uv, .. } = &texture else {
                unreachable!()
            };
            let st = to_uv.transform_point2(uv);
            (
                (st.x * w as f32 - 0.5).floor(),
                (st.y * h as f32 - 0.5).floor(),
            )
        };
        let d = 1e-3;
        let mut checked = 0;
        for i in 0..400 {
            let uv = Vec2::new(
                (i as f32 * 0.754_877).fract(),
                (i as f32 * 0.569_84).fract(),
            );
            let offsets = [Vec2::X * d, -Vec2::X * d, Vec2::Y * d, -Vec2::Y * d];
            if offsets.iter().any(|&o| cell(uv + o) != cell(uv)) {
                continue;
            }
            let f = |uv: Vec2| scalar(texture.eval(uv.into()));
            let fd = Vec2::new(
                (f(uv + offsets[0]) - f(uv + offsets[1])) / (2.0 * d),
                (f(uv + offsets[2]) - f(uv + offsets[3])) / (2.0 * d),
            );
            let g = texture.gradient(uv);
            assert!(
                (g - fd).length() <= 0.01 * (1.0 + fd.length()),
                "at {uv}: gradient {g}, differences {fd}"
            );
            checked += 1;
        }
        assert!(checked > 300, "{checked}");
        // Piecewise constant textures have none.
        let nearest = match texture.clone() {
            Texture::Bitmap {
                bitmap,
                wrap,
                to_uv,
                ..
            } => Texture::Bitmap {
                bitmap,
                filter: FilterType::Nearest,
                wrap,
                to_uv,
            },
            _ => unreachable!(),
        };
        assert_eq!(nearest.gradient(Vec2::new(0.3, 0.3)), Vec2::ZERO);
    }
}
