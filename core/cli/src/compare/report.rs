//! `foton compare --report FILE.html`: one self-contained page (no script, style, image or
//! font from anywhere else) with every image of the comparison as half floats, tabs, zoom to
//! the pixel, exposure, false-colour error images against the reference, the error curves,
//! each run's numbers and the command line (docs/tools.md).
//!
//! The images travel as base64 text of the raw DEFLATE of their half floats, low bytes first
//! and then high bytes (which compresses far better than interleaved). The page's script
//! inflates them synchronously, so that `window.fotonReport` is complete when the page has
//! loaded: `tabs` (the tab names) and `pixel(tab, x, y)` (a tab's linear RGB at column x, row
//! y, row 0 at the top).

use super::json::{json_number as number, json_string};
use super::metrics::Errors;
use flate2::Compression;
use flate2::write::DeflateEncoder;
use foton_core::Rgb;
use foton_core::film::{DisplayTransform, ToneMap};
use half::f16;
use std::io::Write;

/// The page, with `/*FOTON_DATA*/` where the data goes.
const TEMPLATE: &str = include_str!("report.html");

/// One tab: an integrator's render or the reference.
pub struct Tab {
    pub name: String,
    pub reference: bool,
    /// Linear RGB, row-major, top row first.
    pub pixels: Vec<Rgb>,
    /// The per-pixel LDR-FLIP error against the reference.
    pub flip: Option<Vec<f32>>,
    /// Each technique's share of the image (named layers that sum to it).
    pub layers: Vec<(String, Vec<Rgb>)>,
}

/// One render's numbers, a row of the report's table.
pub struct Run {
    pub name: String,
    /// The integrator and its parameters.
    pub description: String,
    /// "16 spp", "23 iterations".
    pub budget: String,
    /// The photon budgets in force, e.g. "global_photons 200000".
    pub photons: String,
    /// None where the images were not rendered here (Python's `foton.compare`).
    pub seconds: Option<f64>,
    /// The process's peak resident memory when the render had ended.
    pub peak_rss_bytes: Option<u64>,
    pub errors: Option<Errors>,
    pub flip: Option<f64>,
}

/// One point of an error curve.
pub struct CurvePoint {
    pub seconds: f64,
    /// Samples per pixel or iterations, where the integrator counts its work so.
    pub work: Option<f64>,
    pub rel_mse: f64,
}

pub struct Report {
    pub title: String,
    /// The command line that reproduces the comparison.
    pub command: String,
    pub width: u32,
    pub height: u32,
    pub display: DisplayTransform,
    pub tabs: Vec<Tab>,
    pub runs: Vec<Run>,
    /// Per integrator, its error curve (empty without --curve).
    pub curves: Vec<(String, Vec<CurvePoint>)>,
}

/// The report of images made elsewhere (Python's `foton.compare(..., report=)`): a tab per
/// named image, then the reference's, with each image's errors and FLIP against it.
pub fn of_images(
    title: &str,
    command: &str,
    width: u32,
    height: u32,
    display: DisplayTransform,
    images: Vec<(String, Vec<Rgb>)>,
    reference: Vec<Rgb>,
) -> Report {
    let r_srgb = super::srgb(&reference, &display);
    let (w, h) = (width as usize, height as usize);
    let mut tabs = Vec::new();
    let mut runs = Vec::new();
    for (name, pixels) in images {
        let (map, mean) = super::flip(
            &r_srgb,
            &super::srgb(&pixels, &display),
            w,
            h,
            super::default_ppd(),
        );
        runs.push(Run {
            name: name.clone(),
            description: String::new(),
            budget: String::new(),
            photons: String::new(),
            seconds: None,
            peak_rss_bytes: None,
            errors: Some(super::errors(&pixels, &reference)),
            flip: Some(mean),
        });
        tabs.push(Tab {
            name,
            reference: false,
            pixels,
            flip: Some(map),
            layers: Vec::new(),
        });
    }
    tabs.push(Tab {
        name: "reference".into(),
        reference: true,
        pixels: reference,
        flip: None,
        layers: Vec::new(),
    });
    Report {
        title: title.into(),
        command: command.into(),
        width,
        height,
        display,
        tabs,
        runs,
        curves: Vec::new(),
    }
}

/// Writes the report's page to `path` atomically.
pub fn write(path: &std::path::Path, report: &Report) -> foton_core::error::Result<()> {
    crate::common::write_atomic(path, html(report).as_bytes())
}

/// The report as one HTML page.
pub fn html(report: &Report) -> String {
    let data = data_json(report);
    // Inside a <script> element, "</" could end it; "<\/" is the same JSON string.
    let data = data.replace("</", "<\\/");
    TEMPLATE.replacen("/*FOTON_DATA*/", &data, 1)
}

fn optional(x: Option<f64>) -> String {
    x.map_or_else(|| "null".into(), number)
}

fn data_json(r: &Report) -> String {
    let tonemap = match r.display.tonemap {
        ToneMap::Clamp => "clamp",
        ToneMap::Filmic => "filmic",
    };
    let tabs: Vec<String> = r
        .tabs
        .iter()
        .map(|t| {
            let layers: Vec<String> = t
                .layers
                .iter()
                .map(|(name, pixels)| {
                    format!(
                        "{{\"name\": {}, \"rgb\": \"{}\"}}",
                        json_string(name),
                        encode_rgb(pixels)
                    )
                })
                .collect();
            format!(
                "{{\"name\": {}, \"reference\": {}, \"rgb\": \"{}\", \"flip\": {}, \"layers\": [{}]}}",
                json_string(&t.name),
                t.reference,
                encode_rgb(&t.pixels),
                t.flip
                    .as_ref()
                    .map_or_else(|| "null".into(), |f| format!("\"{}\"", encode(f))),
                layers.join(", ")
            )
        })
        .collect();
    let runs: Vec<String> = r
        .runs
        .iter()
        .map(|run| {
            format!(
                "{{\"name\": {}, \"description\": {}, \"budget\": {}, \"photons\": {}, \
                 \"seconds\": {}, \"peak_rss_bytes\": {}, \"rel_mse\": {}, \"bias\": {}, \
                 \"flip\": {}}}",
                json_string(&run.name),
                json_string(&run.description),
                json_string(&run.budget),
                json_string(&run.photons),
                optional(run.seconds),
                run.peak_rss_bytes
                    .map_or_else(|| "null".into(), |b| b.to_string()),
                optional(run.errors.map(|e| e.rel_mse)),
                optional(run.errors.map(|e| e.bias)),
                optional(run.flip),
            )
        })
        .collect();
    let curves: Vec<String> = r
        .curves
        .iter()
        .map(|(name, points)| {
            let points: Vec<String> = points
                .iter()
                .map(|p| {
                    format!(
                        "{{\"seconds\": {}, \"work\": {}, \"rel_mse\": {}}}",
                        number(p.seconds),
                        optional(p.work),
                        number(p.rel_mse)
                    )
                })
                .collect();
            format!(
                "{{\"name\": {}, \"points\": [{}]}}",
                json_string(name),
                points.join(", ")
            )
        })
        .collect();
    format!(
        "{{\"title\": {}, \"command\": {}, \"width\": {}, \"height\": {}, \"exposure\": {}, \
         \"tonemap\": \"{tonemap}\",\n\"runs\": [{}],\n\"curves\": [{}],\n\"tabs\": [{}]}}",
        json_string(&r.title),
        json_string(&r.command),
        r.width,
        r.height,
        number(r.display.exposure as f64),
        runs.join(", "),
        curves.join(", "),
        tabs.join(",\n"),
    )
}

fn encode_rgb(pixels: &[Rgb]) -> String {
    let values: Vec<f32> = pixels.iter().flat_map(|p| p.to_array()).collect();
    encode(&values)
}

/// Base64 of the raw DEFLATE of `values` as half floats, all low bytes and then all high
/// bytes (little-endian halves split into two planes).
fn encode(values: &[f32]) -> String {
    let halves: Vec<u16> = values.iter().map(|&v| f16::from_f32(v).to_bits()).collect();
    let mut planes = Vec::with_capacity(2 * halves.len());
    planes.extend(halves.iter().map(|h| (h & 0xff) as u8));
    planes.extend(halves.iter().map(|h| (h >> 8) as u8));
    let mut z = DeflateEncoder::new(Vec::new(), Compression::default());
    z.write_all(&planes).expect("writing to memory");
    base64(&z.finish().expect("writing to memory"))
}

/// Standard base64 (RFC 4648, with padding), as the page's `atob` reads it. Fifteen lines,
/// where a crate would add a dependency for one function.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// `args` as one shell command line: each argument quoted where the shell would split or
/// expand it.
pub fn command_line(args: impl IntoIterator<Item = String>) -> String {
    args.into_iter()
        .map(|a| {
            let plain = !a.is_empty()
                && a.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "-_./:=,+@%".contains(c));
            if plain {
                a
            } else {
                format!("'{}'", a.replace('\'', "'\\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::read::DeflateDecoder;
    use std::io::Read;

    #[test]
    fn base64_is_rfc_4648() {
        // The test vectors of RFC 4648, section 10.
        for (text, b64) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(text.as_bytes()), b64, "{text:?}");
        }
    }

    fn unbase64(s: &str) -> Vec<u8> {
        let value = |c: u8| match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("not base64: {c}"),
        } as u32;
        let mut out = Vec::new();
        for chunk in s.as_bytes().chunks(4) {
            let pad = chunk.iter().filter(|&&c| c == b'=').count();
            let n = chunk
                .iter()
                .map(|&c| if c == b'=' { 0 } else { value(c) })
                .fold(0u32, |n, v| n << 6 | v);
            out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
        }
        out
    }

    #[test]
    fn encoded_values_decode_to_their_half_floats() {
        let values = [0.0f32, 1.0, -2.5, 0.1, 65504.0, 1e-7, 3.0e5, f32::INFINITY];
        let mut planes = Vec::new();
        DeflateDecoder::new(&unbase64(&encode(&values))[..])
            .read_to_end(&mut planes)
            .unwrap();
        assert_eq!(planes.len(), 2 * values.len());
        let n = values.len();
        for (i, v) in values.iter().enumerate() {
            let h = f16::from_bits(planes[i] as u16 | (planes[n + i] as u16) << 8);
            assert_eq!(h, f16::from_f32(*v), "{v}");
        }
        // Half precision: 11 significant bits.
        let h = f16::from_bits(planes[3] as u16 | (planes[n + 3] as u16) << 8).to_f32();
        assert!((h - 0.1).abs() < 0.1 / 1024.0, "{h}");
    }

    #[test]
    fn the_page_holds_its_data_and_nothing_from_elsewhere() {
        let report = Report {
            title: "a </script> title".into(),
            command: "foton compare 'a b.toml'".into(),
            width: 2,
            height: 1,
            display: DisplayTransform::default(),
            tabs: vec![Tab {
                name: "path".into(),
                reference: false,
                pixels: vec![Rgb::new(1.0, 2.0, 3.0), Rgb::ZERO],
                flip: None,
                layers: Vec::new(),
            }],
            runs: Vec::new(),
            curves: Vec::new(),
        };
        let page = html(&report);
        assert!(!page.contains("/*FOTON_DATA*/"));
        assert!(page.contains(r#""title": "a <\/script> title""#), "{page}");
        assert_eq!(page.matches("</script>").count(), 1);
        // No resource from anywhere else: no src= or href= but the empty inline icon, no
        // url(), @import or fetch.
        for needle in [
            "src=",
            "url(",
            "@import",
            "fetch(",
            "XMLHttpRequest",
            "http://",
            "https://",
        ] {
            let allowed = needle == "http://"
                && page.matches(needle).count() == 1
                && page.contains("http://www.w3.org/2000/svg");
            assert!(
                !page.contains(needle) || allowed,
                "the page holds {needle:?}"
            );
        }
        assert_eq!(page.matches("href=").count(), 1);
        assert!(page.contains(r#"<link rel="icon" href="data:,">"#));
    }

    #[test]
    fn command_lines_quote_what_the_shell_would_split() {
        assert_eq!(
            command_line(
                [
                    "foton",
                    "compare",
                    "a b.toml",
                    "--set",
                    "render.spp=4",
                    "it's"
                ]
                .map(String::from)
            ),
            "foton compare 'a b.toml' --set render.spp=4 'it'\\''s'"
        );
    }
}
