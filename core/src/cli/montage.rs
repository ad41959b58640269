//! Labelled images for the seeing-and-comparing commands (`photons`, `compare`, `sweep`): a
//! grid of tiles, each under a band of text in an 8x8 bitmap font (font8x8), white on dark
//! grey.
//!
//! Pixels are linear RGB like a film's, and the result is written with `film::write_image`,
//! so a PNG gets the same display transform as every render: clamp to [0, 1], then the sRGB
//! curve. Colours chosen for display (the false-colour map) are therefore stored decoded.
//!
//! Layout: cells as large as the largest tile, `BORDER` pixels around and between them; the
//! label bands of a row have the height of the row's longest label, so the images line up.

use crate::Rgb;
use crate::error::Result;
use crate::film::{Film, srgb_decode, write_image};
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

    fn fill_rect(&mut self, x0: u32, y0: u32, w: u32, h: u32, c: Rgb) {
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

    /// Writes the image atomically (.png: sRGB 8-bit; .exr: linear float).
    pub fn write(&self, path: &Path) -> Result<()> {
        write_image(path, self.width, self.height, &self.pixels)
    }
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

/// Draws one line of text with its top-left corner at (x, y), `scale` pixels per font pixel;
/// nothing right of `x_max`. Characters outside ASCII are drawn as `?`.
pub fn draw_text(img: &mut Image, x: u32, y: u32, x_max: u32, text: &str, scale: u32) {
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
            img.fill_rect(x0, y0, cell_w, *band, BAND);
            for (l, line) in lines.iter().enumerate() {
                let y = y0 + scale * (PAD + l as u32 * (GLYPH + LINE_GAP));
                draw_text(&mut img, x0 + scale * PAD, y, x0 + cell_w, line, scale);
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
        assert_eq!(img.pixels.len(), (img.width * img.height) as usize);
        // The first tile's image lies below its band; its band has text in it.
        assert_eq!(img.get(BORDER, BORDER + band), Rgb::splat(0.5));
        let band_pixels: Vec<Rgb> = (0..band)
            .flat_map(|y| (0..32).map(move |x| (x, y)))
            .map(|(x, y)| img.get(BORDER + x, BORDER + y))
            .collect();
        assert!(band_pixels.contains(&INK));
        assert!(band_pixels.contains(&BAND));
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
}
