//! Labelled images for the seeing-and-comparing commands (`photons`, `compare`, `sweep`): a
//! grid of tiles, each under a band of text in an 8x8 bitmap font (font8x8), white on dark
//! grey.
//!
//! Pixels are display values, linear (before the sRGB curve) and in [0, 1]: a render enters
//! through [`render_image`], which applies the scene's exposure and tone map when the montage
//! is a PNG, so that a render looks in a montage as `foton render` writes it; colours chosen
//! for display (text, the false-colour map) are stored sRGB-decoded. The montage is written
//! with `foton_loader::image::write_image` and the plain clamp, which leaves such values as they are.
//!
//! Layout: cells as large as the largest tile, `BORDER` pixels around and between them; the
//! label bands of a row have the height of the row's longest label, so the images line up.

use foton_core::Rgb;
use foton_core::error::Result;
use foton_core::film::{DisplayTransform, Film, ImageFormat, format_of, srgb_decode};
use foton_loader::image::write_image;
use std::path::Path;

/// Pixels around and between the cells of a grid.
pub const BORDER: u32 = 4;
/// Pixels between a label band's edge and its text (times the text scale).
pub const PAD: u32 = 3;
/// Pixels between two lines of a label (times the text scale).
pub const LINE_GAP: u32 = 2;
/// Glyph size of the font (square).
pub const GLYPH: u32 = 8;

/// The borders around the cells (linear; black).
const BACKGROUND: Rgb = Rgb::ZERO;
/// The label bands: dark grey (linear 0.03, about 48/255 once sRGB-encoded).
const BAND: Rgb = Rgb::splat(0.03);
const INK: Rgb = Rgb::ONE;

/// A linear RGB image, row-major from the top-left.
#[derive(Clone, Debug)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Rgb>,
}

impl Image {
    pub fn new(width: u32, height: u32, fill: Rgb) -> Image {
        Image {
            width,
            height,
            pixels: vec![fill; width as usize * height as usize],
        }
    }

    pub fn from_film(film: &Film) -> Image {
        Image {
            width: film.width,
            height: film.height,
            pixels: film.pixels(),
        }
    }

    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Rgb {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Sets a pixel; outside the image: nothing.
    #[inline]
    pub fn put(&mut self, x: i64, y: i64, c: Rgb) {
        if x >= 0 && y >= 0 && x < self.width as i64 && y < self.height as i64 {
            self.pixels[y as usize * self.width as usize + x as usize] = c;
        }
    }

    /// Fills `w` x `h` pixels from the corner (x0, y0) with `c`.
    fn fill_rect(&mut self, (x0, y0): (u32, u32), (w, h): (u32, u32), c: Rgb) {
        for y in y0..(y0 + h).min(self.height) {
            for x in x0..(x0 + w).min(self.width) {
                self.put(x as i64, y as i64, c);
            }
        }
    }

    /// Copies `src` with its top-left corner at (x, y), clamped to [0, 1] for display (an
    /// HDR render would otherwise stay HDR in an EXR montage while the PNG clips it).
    fn blit_display(&mut self, src: &Image, x: u32, y: u32) {
        for sy in 0..src.height {
            for sx in 0..src.width {
                let c = src.get(sx, sy);
                let c = if c.is_finite() {
                    c.clamp(Rgb::ZERO, Rgb::ONE)
                } else {
                    Rgb::ZERO
                };
                self.put((x + sx) as i64, (y + sy) as i64, c);
            }
        }
    }

    /// Writes the image atomically (.png: sRGB 8-bit; .exr: linear float). Its pixels are
    /// display values already: no exposure or tone map is applied.
    pub fn write(&self, path: &Path) -> Result<()> {
        write_image(
            path,
            self.width,
            self.height,
            &self.pixels,
            &DisplayTransform::default(),
        )
    }
}

/// A render as a montage written to `output` shows it: for a PNG, through `display` (the
/// scene's exposure and tone map), as `foton render` would write it; for an EXR, the radiance
/// unscaled (an EXR never gets the display transform), clamped by the grid.
pub fn render_image(film: &Film, display: &DisplayTransform, output: &Path) -> Image {
    let mut image = Image::from_film(film);
    if matches!(format_of(output), Ok(ImageFormat::Png)) {
        for p in &mut image.pixels {
            *p = display.map(*p);
        }
    }
    image
}

/// One cell of a grid: an image and its label, one string per line (long lines are wrapped
/// to the cell's width).
#[derive(Clone, Debug)]
pub struct Tile {
    pub image: Image,
    pub label: Vec<String>,
}

/// The text scale for cells `width` pixels wide: 8-pixel glyphs up to 511 pixels, doubled
/// from 512, and so on up to 4x, so that a label stays legible on a large image without
/// taking over a small one.
pub fn text_scale(width: u32) -> u32 {
    (width / 256).clamp(1, 4)
}

/// Splits `text` into lines of at most `max_chars` characters, at spaces where it can and
/// inside words that are longer than a line.
pub fn wrap(text: &str, max_chars: usize) -> Vec<String> {
    let max_chars = max_chars.max(1);
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let mut word: Vec<char> = word.chars().collect();
        let len = line.chars().count();
        if len > 0 && len + 1 + word.len() <= max_chars {
            line.push(' ');
            line.extend(&word);
            continue;
        }
        if len > 0 {
            lines.push(std::mem::take(&mut line));
        }
        while word.len() > max_chars {
            let rest = word.split_off(max_chars);
            lines.push(word.into_iter().collect());
            word = rest;
        }
        line.extend(&word);
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// The lines a label takes in a cell `width` pixels wide at text scale `scale`.
pub fn label_lines(label: &[String], width: u32, scale: u32) -> Vec<String> {
    let usable = width.saturating_sub(2 * PAD * scale);
    let max_chars = (usable / (GLYPH * scale)).max(1) as usize;
    label.iter().flat_map(|l| wrap(l, max_chars)).collect()
}

/// Height of a label band with `lines` lines at text scale `scale` (0 for no label).
pub fn band_height(lines: usize, scale: u32) -> u32 {
    if lines == 0 {
        return 0;
    }
    let lines = lines as u32;
    scale * (2 * PAD + lines * GLYPH + (lines - 1) * LINE_GAP)
}

/// How [`draw_text`] draws: `scale` pixels per font pixel, nothing right of `x_max`.
#[derive(Clone, Copy, Debug)]
pub struct TextStyle {
    pub scale: u32,
    pub x_max: u32,
}

/// Draws one line of text with its top-left corner at (x, y). Characters outside ASCII are
/// drawn as `?`.
pub fn draw_text(img: &mut Image, (x, y): (u32, u32), text: &str, style: TextStyle) {
    let TextStyle { scale, x_max } = style;
    let mut cx = x;
    for ch in text.chars() {
        if cx + GLYPH * scale > x_max {
            break;
        }
        let code = if ch.is_ascii() {
            ch as usize
        } else {
            b'?' as usize
        };
        let glyph = font8x8::legacy::BASIC_LEGACY[code];
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..GLYPH {
                // Bit 0 is the glyph's leftmost pixel.
                if bits >> col & 1 == 0 {
                    continue;
                }
                let px = cx + col * scale;
                let py = y + row as u32 * scale;
                for dy in 0..scale {
                    for dx in 0..scale {
                        img.put((px + dx) as i64, (py + dy) as i64, INK);
                    }
                }
            }
        }
        cx += GLYPH * scale;
    }
}

/// Lays `tiles` out row-major in a grid `columns` cells wide, each label in a band above its
/// image. Cells take the size of the largest tile (smaller tiles sit in their top-left
/// corner); the bands of a row take the height of its longest label.
pub fn grid(tiles: &[Tile], columns: usize) -> Image {
    let columns = columns.clamp(1, tiles.len().max(1));
    let cell_w = tiles.iter().map(|t| t.image.width).max().unwrap_or(0);
    let cell_h = tiles.iter().map(|t| t.image.height).max().unwrap_or(0);
    let scale = text_scale(cell_w);
    let lines: Vec<Vec<String>> = tiles
        .iter()
        .map(|t| label_lines(&t.label, cell_w, scale))
        .collect();
    let bands: Vec<u32> = lines
        .chunks(columns)
        .map(|row| band_height(row.iter().map(Vec::len).max().unwrap_or(0), scale))
        .collect();
    let width = columns as u32 * (cell_w + BORDER) + BORDER;
    let height = bands.iter().map(|b| b + cell_h + BORDER).sum::<u32>() + BORDER;
    let mut img = Image::new(width, height, BACKGROUND);
    let mut y0 = BORDER;
    for ((row, row_lines), band) in tiles.chunks(columns).zip(lines.chunks(columns)).zip(&bands) {
        for (i, (tile, lines)) in row.iter().zip(row_lines).enumerate() {
            let x0 = BORDER + i as u32 * (cell_w + BORDER);
            img.fill_rect((x0, y0), (cell_w, *band), BAND);
            let style = TextStyle {
                scale,
                x_max: x0 + cell_w,
            };
            for (l, line) in lines.iter().enumerate() {
                let y = y0 + scale * (PAD + l as u32 * (GLYPH + LINE_GAP));
                draw_text(&mut img, (x0 + scale * PAD, y), line, style);
            }
            img.blit_display(&tile.image, x0, y0 + band);
        }
        y0 += band + cell_h + BORDER;
    }
    img
}

/// A diverging false-colour map for a signed relative difference: blue below zero, light grey
/// at zero, red above, saturated at |d| >= 1 (Moreland's cool-to-warm end points, blended in
/// sRGB). NaN is black.
pub fn diverging(d: f32) -> Rgb {
    const COOL: [f32; 3] = [59.0, 76.0, 192.0];
    const MID: [f32; 3] = [221.0, 221.0, 221.0];
    const WARM: [f32; 3] = [180.0, 4.0, 38.0];
    if d.is_nan() {
        return Rgb::ZERO;
    }
    let t = d.clamp(-1.0, 1.0);
    let (end, t) = if t < 0.0 { (COOL, -t) } else { (WARM, t) };
    let c = |i: usize| srgb_decode((MID[i] + (end[i] - MID[i]) * t) / 255.0);
    Rgb::new(c(0), c(1), c(2))
}

// ---------------------------------------------------------------------------------------------
// A log-log plot of a few series of points (compare's error curve)
// ---------------------------------------------------------------------------------------------

/// Size of the image `log_log_plot` draws.
pub const PLOT_WIDTH: u32 = 640;
pub const PLOT_HEIGHT: u32 = 480;
/// The plot area inside it: left, top, right, bottom edges (the legend goes right of it).
const PLOT_AREA: (u32, u32, u32, u32) = (72, 40, 496, 432);

/// The plot area's grid lines and frame (its background is black).
const GRID: Pen = Pen {
    width: 1,
    colour: Rgb::splat(0.06),
};
const FRAME: Pen = Pen {
    width: 1,
    colour: Rgb::splat(0.35),
};
/// The width of the series' lines (each in its colour).
const SERIES_WIDTH: u32 = 2;

/// How a line is drawn: its width in pixels and its colour.
#[derive(Clone, Copy, Debug)]
struct Pen {
    width: u32,
    colour: Rgb,
}

/// One named series of (x, y) points, drawn as a polyline with a marker at each point.
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// Okabe and Ito's colour-blind-safe palette (sRGB bytes), in series order: orange, sky blue,
/// bluish green, yellow, blue, vermillion, reddish purple.
const PALETTE: [[u8; 3]; 7] = [
    [230, 159, 0],
    [86, 180, 233],
    [0, 158, 115],
    [240, 228, 66],
    [0, 114, 178],
    [213, 94, 0],
    [204, 121, 167],
];

/// The colour of series `i` (linear, for the display transform of `Image::write`).
pub fn series_colour(i: usize) -> Rgb {
    let c = PALETTE[i % PALETTE.len()];
    let d = |b: u8| srgb_decode(b as f32 / 255.0);
    Rgb::new(d(c[0]), d(c[1]), d(c[2]))
}

/// The k-th value of the 1-2-5 sequence: ..., 0.5, 1, 2, 5, 10, 20, ... (k = 0 is 1).
fn one_two_five(k: i32) -> f64 {
    [1.0, 2.0, 5.0][k.rem_euclid(3) as usize] * 10f64.powi(k.div_euclid(3))
}

/// The index of the largest 1-2-5 value not above `x` (> 0), up to rounding.
fn one_two_five_below(x: f64) -> i32 {
    let x = x * (1.0 + 1e-9);
    let e = x.log10().floor() as i32;
    let m = x / 10f64.powi(e);
    3 * e + if m >= 5.0 { 2 } else { i32::from(m >= 2.0) }
}

/// The ticks of a logarithmic axis covering [lo, hi] (0 < lo <= hi): the axis runs from the
/// 1-2-5 value at or below `lo` to the one at or above `hi` (one step either side if they
/// meet), ticked at every 1-2-5 value; over more than 10 ticks, at the powers of ten only (and
/// every other one, and so on, until at most 10 are left). Returns (axis lo, axis hi, ticks).
pub fn log_ticks(lo: f64, hi: f64) -> (f64, f64, Vec<f64>) {
    let mut a = one_two_five_below(lo);
    let mut b = one_two_five_below(hi);
    if one_two_five(b) < hi * (1.0 - 1e-9) {
        b += 1;
    }
    if a == b {
        a -= 1;
        b += 1;
    }
    if b - a < 10 {
        return (
            one_two_five(a),
            one_two_five(b),
            (a..=b).map(one_two_five).collect(),
        );
    }
    let (lo_e, hi_e) = (a.div_euclid(3), (b + 2).div_euclid(3));
    let stride = ((hi_e - lo_e) as usize).div_ceil(9).max(1);
    let ticks = (lo_e..=hi_e)
        .step_by(stride)
        .map(|e| 10f64.powi(e))
        .collect();
    (10f64.powi(lo_e), 10f64.powi(hi_e), ticks)
}

/// A tick label: plain decimals from 0.01 to 9999 ("0.05", "2", "500"), else "2e-3", "1e5".
pub fn tick_label(v: f64) -> String {
    let e = (v * (1.0 + 1e-9)).log10().floor() as i32;
    if (-2..4).contains(&e) {
        format!("{:.*}", (-e).max(0) as usize, v)
    } else {
        format!("{}e{e}", (v / 10f64.powi(e)).round())
    }
}

impl Image {
    /// A line from `from` to `to` drawn with `pen`, kept inside `clip` (left, top, right,
    /// bottom).
    fn line(&mut self, from: (f64, f64), to: (f64, f64), pen: Pen, clip: (u32, u32, u32, u32)) {
        let Pen { width, colour: c } = pen;
        let steps = ((to.0 - from.0).abs().max((to.1 - from.1).abs()) * 2.0)
            .ceil()
            .max(1.0) as u32;
        let half = (width as f64 - 1.0) / 2.0;
        for i in 0..=steps {
            let t = i as f64 / steps as f64;
            let x = from.0 + (to.0 - from.0) * t - half;
            let y = from.1 + (to.1 - from.1) * t - half;
            for dy in 0..width {
                for dx in 0..width {
                    let (px, py) = (
                        (x + dx as f64).round() as i64,
                        (y + dy as f64).round() as i64,
                    );
                    if px >= clip.0 as i64
                        && py >= clip.1 as i64
                        && px <= clip.2 as i64
                        && py <= clip.3 as i64
                    {
                        self.put(px, py, c);
                    }
                }
            }
        }
    }

    /// A filled marker 9 pixels across centred on (x, y): square, disc, diamond or triangle
    /// for shapes 0, 1, 2, 3 (and so on, cyclically).
    fn marker(&mut self, x: f64, y: f64, shape: usize, c: Rgb) {
        let (cx, cy) = (x.round() as i64, y.round() as i64);
        for dy in -4i64..=4 {
            for dx in -4i64..=4 {
                let inside = match shape % 4 {
                    0 => dx.abs() <= 3 && dy.abs() <= 3,
                    1 => dx * dx + dy * dy <= 17,
                    2 => dx.abs() + dy.abs() <= 4,
                    // Apex at the top: the half-width grows by one every two rows.
                    _ => (-4..=3).contains(&dy) && 2 * dx.abs() <= dy + 4,
                };
                if inside {
                    self.put(cx + dx, cy + dy, c);
                }
            }
        }
    }
}

/// A log-log plot, `PLOT_WIDTH` x `PLOT_HEIGHT`: each series a polyline in its colour
/// (`series_colour`) with a marker at each point (`marker` shapes in turn), over a grid at the
/// ticks of `log_ticks` on both axes, labelled with `tick_label`; `title` above, `x_label`
/// under the x axis, `y_label` above the y axis, and a legend (marker, line and name of each
/// series) right of the plot. Points with a coordinate that is not a positive number are left
/// out (a series' line joins the points that are left). White text on dark grey, the plot area
/// black, as the labels of `grid`.
pub fn log_log_plot(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> Image {
    let mut img = Image::new(PLOT_WIDTH, PLOT_HEIGHT, BAND);
    let (left, top, right, bottom) = PLOT_AREA;
    img.fill_rect(
        (left, top),
        (right - left + 1, bottom - top + 1),
        BACKGROUND,
    );

    let plotted: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .copied()
                .filter(|&(x, y)| x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite())
                .collect()
        })
        .collect();
    let all = || plotted.iter().flatten();
    let range = |coord: fn(&(f64, f64)) -> f64| {
        let lo = all().map(coord).fold(f64::INFINITY, f64::min);
        let hi = all().map(coord).fold(0.0, f64::max);
        if lo.is_finite() {
            (lo, hi)
        } else {
            (1.0, 10.0)
        }
    };
    let (x_lo, x_hi, x_ticks) = {
        let (lo, hi) = range(|p| p.0);
        log_ticks(lo, hi)
    };
    let (y_lo, y_hi, y_ticks) = {
        let (lo, hi) = range(|p| p.1);
        log_ticks(lo, hi)
    };
    let to_px = |x: f64, y: f64| {
        let tx = (x / x_lo).ln() / (x_hi / x_lo).ln();
        let ty = (y / y_lo).ln() / (y_hi / y_lo).ln();
        (
            left as f64 + tx * (right - left) as f64,
            bottom as f64 - ty * (bottom - top) as f64,
        )
    };

    // Grid and tick labels.
    let all_area = (0, 0, PLOT_WIDTH - 1, PLOT_HEIGHT - 1);
    let text = TextStyle {
        scale: 1,
        x_max: PLOT_WIDTH,
    };
    for &t in &x_ticks {
        let (x, _) = to_px(t, y_lo);
        img.line((x, top as f64), (x, bottom as f64), GRID, all_area);
        let label = tick_label(t);
        let w = label.len() as f64 * GLYPH as f64;
        let lx = (x - w / 2.0).clamp(0.0, (PLOT_WIDTH as f64 - w).max(0.0)) as u32;
        draw_text(&mut img, (lx, bottom + 6), &label, text);
    }
    for &t in &y_ticks {
        let (_, y) = to_px(x_lo, t);
        img.line((left as f64, y), (right as f64, y), GRID, all_area);
        let label = tick_label(t);
        let lx = left.saturating_sub(6 + label.len() as u32 * GLYPH);
        let left_of_area = TextStyle {
            x_max: left,
            ..text
        };
        draw_text(
            &mut img,
            (lx, (y - 4.0).max(0.0) as u32),
            &label,
            left_of_area,
        );
    }
    for (from, to) in [
        ((left, top), (right, top)),
        ((right, top), (right, bottom)),
        ((right, bottom), (left, bottom)),
        ((left, bottom), (left, top)),
    ] {
        let f = |p: (u32, u32)| (p.0 as f64, p.1 as f64);
        img.line(f(from), f(to), FRAME, all_area);
    }

    // Titles.
    draw_text(&mut img, (PAD * 2, 10), title, text);
    draw_text(&mut img, (PAD * 2, top - 14), y_label, text);
    let w = x_label.len() as u32 * GLYPH;
    let x = (left + right).saturating_sub(w) / 2;
    draw_text(&mut img, (x, bottom + 24), x_label, text);

    // The series, then the legend.
    let area = (left, top, right, bottom);
    for (i, points) in plotted.iter().enumerate() {
        let c = series_colour(i);
        let pen = Pen {
            width: SERIES_WIDTH,
            colour: c,
        };
        for pair in points.windows(2) {
            img.line(
                to_px(pair[0].0, pair[0].1),
                to_px(pair[1].0, pair[1].1),
                pen,
                area,
            );
        }
        for &(x, y) in points {
            let (px, py) = to_px(x, y);
            img.marker(px, py, i, c);
        }
    }
    for (i, s) in series.iter().enumerate() {
        let c = series_colour(i);
        let y = top + 8 + i as u32 * 20;
        let x = right + 16;
        let pen = Pen {
            width: SERIES_WIDTH,
            colour: c,
        };
        img.line(
            (x as f64, y as f64),
            ((x + 24) as f64, y as f64),
            pen,
            all_area,
        );
        img.marker((x + 12) as f64, y as f64, i, c);
        draw_text(&mut img, (x + 32, y - 4), &s.name, text);
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_breaks_at_spaces_and_inside_long_words() {
        assert_eq!(wrap("a bb ccc", 4), ["a bb", "ccc"]);
        assert_eq!(wrap("abcdefghij", 4), ["abcd", "efgh", "ij"]);
        assert_eq!(wrap("", 4), [""]);
        assert_eq!(wrap("x  y", 10), ["x y"]);
        for line in wrap("photon(global_photons = 200000, k = 50, kernel = box)", 12) {
            assert!(line.chars().count() <= 12, "{line}");
        }
    }

    #[test]
    fn grid_has_the_size_of_its_layout() {
        let tile = |w, h, label: &str| Tile {
            image: Image::new(w, h, Rgb::splat(0.5)),
            label: vec![label.to_string()],
        };
        let tiles = [
            tile(32, 16, "a"),
            tile(32, 16, "b"),
            tile(32, 16, "c"),
            tile(30, 10, "d ef gh"),
        ];
        let img = grid(&tiles, 3);
        let band = band_height(1, 1);
        // The second row's label takes three lines of (32 - 2 PAD) / 8 = 3 characters.
        let band2 = band_height(3, 1);
        assert_eq!(
            (img.width, img.height),
            (3 * 32 + 4 * BORDER, band + band2 + 2 * 16 + 3 * BORDER)
        );
        // The first tile's image lies below its band; its band has text in it.
        assert_eq!(img.get(BORDER, BORDER + band), Rgb::splat(0.5));
        let band_pixels: Vec<Rgb> = (0..band)
            .flat_map(|y| (0..32).map(move |x| (x, y)))
            .map(|(x, y)| img.get(BORDER + x, BORDER + y))
            .collect();
        assert!(band_pixels.contains(&INK));
        assert!(band_pixels.contains(&BAND));
        // The smaller fourth tile (30x10) starts the second row, below its three-line band, at
        // the top left of its 32x16 cell; the rest of the cell is background.
        let top = BORDER + band + 16 + BORDER + band2;
        assert_eq!(img.get(BORDER, top), Rgb::splat(0.5));
        assert_eq!(img.get(BORDER + 29, top + 9), Rgb::splat(0.5));
        assert_ne!(img.get(BORDER, top - 1), Rgb::splat(0.5), "its band");
        assert_eq!(img.get(BORDER + 30, top), BACKGROUND);
        assert_eq!(img.get(BORDER, top + 10), BACKGROUND);
    }

    #[test]
    fn diverging_map_is_grey_at_zero_and_blue_below_red_above() {
        let zero = diverging(0.0);
        assert!((zero.x - zero.y).abs() < 1e-6 && (zero.y - zero.z).abs() < 1e-6);
        let below = diverging(-0.5);
        assert!(below.z > below.x);
        let above = diverging(0.5);
        assert!(above.x > above.z);
        assert_eq!(diverging(3.0), diverging(1.0));
        assert_eq!(diverging(f32::NAN), Rgb::ZERO);
    }

    #[test]
    fn log_ticks_follow_one_two_five_and_cover_the_range() {
        let (lo, hi, ticks) = log_ticks(0.3, 7.0);
        assert_eq!((lo, hi), (0.2, 10.0));
        assert_eq!(ticks, [0.2, 0.5, 1.0, 2.0, 5.0, 10.0]);
        // Values on the sequence are their own ends; a single value gets a step either side.
        assert_eq!(log_ticks(1.0, 20.0).2, [1.0, 2.0, 5.0, 10.0, 20.0]);
        assert_eq!(log_ticks(2.0, 2.0).2, [1.0, 2.0, 5.0]);
        // Six decades: powers of ten only.
        let (lo, hi, ticks) = log_ticks(3e-5, 0.4);
        assert_eq!((lo, hi), (1e-5, 1.0));
        assert_eq!(ticks.len(), 6);
        let labels: Vec<String> = [1e-5, 2e-3, 0.01, 0.05, 1.0, 20.0, 500.0, 1e4]
            .iter()
            .map(|&v| tick_label(v))
            .collect();
        assert_eq!(
            labels,
            ["1e-5", "2e-3", "0.01", "0.05", "1", "20", "500", "1e4"]
        );
    }

    #[test]
    fn plot_has_its_size_and_draws_each_series_in_its_colour() {
        let series = [
            Series {
                name: "path".into(),
                points: vec![(0.5, 0.2), (1.0, 0.1), (2.0, 0.05)],
            },
            Series {
                name: "photon".into(),
                // A point at zero error cannot be drawn on a log axis: left out.
                points: vec![(0.6, 0.03), (1.1, 0.0), (2.1, 0.02)],
            },
        ];
        let img = log_log_plot("title", "seconds", "rel. MSE", &series);
        assert_eq!((img.width, img.height), (PLOT_WIDTH, PLOT_HEIGHT));
        let count = |c: Rgb| img.pixels.iter().filter(|&&p| p == c).count();
        assert!(count(series_colour(0)) > 100 && count(series_colour(1)) > 100);
        assert!(count(INK) > 100, "text");
        assert_ne!(series_colour(0), series_colour(1));
    }
}
