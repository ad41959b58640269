//! The part files of a render split with `foton render --part I/N`, which `foton merge` adds
//! up (`merge.rs`).
//!
//! A part file is an OpenEXR image. Its `R`, `G`, `B` channels are the part's own image (any
//! EXR viewer shows it); what the merge uses are the exact sums: per pixel the sample count
//! `N` (u32) and, per colour channel, the film's fixed-point sum (an i128,
//! [`RadianceSum`]) as four u32 words `sum.R.0` (least significant) to `sum.R.3`. Integer sums
//! add associatively, so the merged sums, and the image made from them, are bit for bit those
//! of the render done in one process. A film with splats (light paths connected to the camera,
//! `bdpt`) stores its splat sums the same way, `splat.R.0` to `splat.B.3`: they are added
//! apart from the pixels' own sums, and the merged image scales them by the samples of all the
//! parts together, as the render in one process does (`Film::pixel`). The header carries what
//! decides whether parts belong together (attributes `foton.*`, below): the scene's content
//! hash, the integrator with its parameters, the seed, the build of foton, the part I/N, and
//! how much of its share the part did (an interrupted part says so).

use crate::common::write_atomic_with;
use exr::prelude::*;
use foton_core::film::{DisplayTransform, Film, ImageFormat, RadianceSum, ToneMap, format_of};
use foton_core::integrator::Part;
use foton_core::scene::Scene;
use foton_core::{Error, Result as FotonResult};
use std::collections::BTreeMap;
use std::path::Path;

/// The version of the part file layout (attribute `foton.format`).
/// 2 added the splat channels: a foton that read only format 1 would merge a splatting part
/// without its splats, so format 1 parts are refused (render them again); 3 added the film's
/// colour matrix (`foton.colorMatrix`).
pub const FORMAT: &str = "foton-part 3";

const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// What a part file says about itself.
#[derive(Clone, Debug, PartialEq)]
pub struct PartInfo {
    pub part: Part,
    /// The scene file as the render was given it (for messages).
    pub scene: String,
    /// [`scene_hash`] of the scene with its overrides.
    pub scene_hash: String,
    /// The integrator with its parameters in force (`Integrator::describe`).
    pub integrator: String,
    pub seed: u64,
    /// `foton_core::BUILD_ID` of the foton that rendered it.
    pub build: String,
    pub width: u32,
    pub height: u32,
    /// What the work is counted in: `samples` (per pixel) or `iterations`.
    pub work: String,
    /// The units of work in this part's share, and how many it did (fewer: interrupted).
    pub planned: u64,
    pub done: u64,
    /// The scene's display transform, for a merged PNG.
    pub exposure: f32,
    pub tonemap: String,
    /// The film's response (`[film] white_balance`), applied to the merged image.
    pub color_matrix: Option<glam::DMat3>,
}

impl PartInfo {
    /// The description of a part of `scene` that `film` holds.
    pub fn of(
        scene: &Scene,
        overrides: &[String],
        integrator: &str,
        film: &Film,
    ) -> FotonResult<PartInfo> {
        let (work, planned, done) = if film.iterations > 0 || film.iterations_planned > 0 {
            ("iterations", film.iterations_planned, film.iterations)
        } else {
            let share = film.part.share(scene.render().spp as u64);
            let done = film.counts().iter().copied().min().unwrap_or(0) as u64;
            ("samples", share.end - share.start, done)
        };
        let display = scene.film().display();
        Ok(PartInfo {
            part: film.part,
            scene: scene.file().display().to_string(),
            scene_hash: scene_hash(scene, overrides)?,
            integrator: integrator.to_string(),
            seed: scene.render().seed,
            build: foton_core::BUILD_ID.to_string(),
            width: film.width,
            height: film.height,
            work: work.into(),
            planned,
            done,
            exposure: display.exposure,
            tonemap: display.tonemap.name().into(),
            color_matrix: scene.film().color_matrix(),
        })
    }

    fn attributes(&self) -> Vec<(&'static str, String)> {
        vec![
            ("foton.format", FORMAT.into()),
            ("foton.part", self.part.to_string()),
            ("foton.scene", self.scene.clone()),
            ("foton.sceneHash", self.scene_hash.clone()),
            ("foton.integrator", self.integrator.clone()),
            ("foton.seed", self.seed.to_string()),
            ("foton.build", self.build.clone()),
            ("foton.work", self.work.clone()),
            ("foton.planned", self.planned.to_string()),
            ("foton.done", self.done.to_string()),
            ("foton.exposure", self.exposure.to_string()),
            ("foton.tonemap", self.tonemap.clone()),
            (
                "foton.colorMatrix",
                // Column-major, each number as Rust prints it back exactly.
                self.color_matrix.map_or_else(
                    || "none".into(),
                    |m| m.to_cols_array().map(|x| format!("{x:?}")).join(" "),
                ),
            ),
        ]
    }

    fn from_attributes(
        path: &Path,
        size: (usize, usize),
        get: impl Fn(&str) -> Option<String>,
    ) -> FotonResult<PartInfo> {
        let format = get("foton.format").ok_or_else(|| {
            Error::io(
                path,
                "not a foton part (no foton.format attribute): parts are written by `foton render --part I/N`",
            )
        })?;
        if format != FORMAT {
            return Err(Error::io(
                path,
                format!(
                    "a part in format `{format}`; this foton reads `{FORMAT}` (parts written by \
                     another version of foton cannot be merged: render them again)"
                ),
            ));
        }
        let field = |key: &str| {
            get(key).ok_or_else(|| Error::io(path, format!("damaged part: no {key} attribute")))
        };
        let number = |key: &str| -> FotonResult<u64> {
            let text = field(key)?;
            text.parse().map_err(|_| {
                Error::io(
                    path,
                    format!("damaged part: {key} = `{text}` is not a number"),
                )
            })
        };
        let part_text = field("foton.part")?;
        let part = parse_part(&part_text)
            .map_err(|e| Error::io(path, format!("damaged part: foton.part: {e}")))?;
        Ok(PartInfo {
            part,
            scene: field("foton.scene")?,
            scene_hash: field("foton.sceneHash")?,
            integrator: field("foton.integrator")?,
            seed: number("foton.seed")?,
            build: field("foton.build")?,
            width: size.0 as u32,
            height: size.1 as u32,
            work: field("foton.work")?,
            planned: number("foton.planned")?,
            done: number("foton.done")?,
            exposure: field("foton.exposure")?.parse().unwrap_or(0.0),
            tonemap: field("foton.tonemap")?,
            color_matrix: match field("foton.colorMatrix")?.as_str() {
                "none" => None,
                text => {
                    let m: Vec<f64> = text
                        .split_whitespace()
                        .filter_map(|x| x.parse().ok())
                        .collect();
                    let m: [f64; 9] = m.try_into().map_err(|_| {
                        Error::io(
                            path,
                            format!("damaged part: foton.colorMatrix = `{text}` is not 9 numbers"),
                        )
                    })?;
                    Some(glam::DMat3::from_cols_array(&m))
                }
            },
        })
    }

    /// The scene's display transform, for a PNG of the part or of the merge.
    pub fn display(&self) -> DisplayTransform {
        DisplayTransform::new(
            self.exposure,
            ToneMap::from_name(&self.tonemap).unwrap_or_default(),
        )
    }
}

/// `I/N` with 0 <= I < N, as `--part` takes it.
pub fn parse_part(text: &str) -> std::result::Result<Part, String> {
    let bad = || format!("`{text}`: expected I/N with 0 <= I < N, e.g. 0/4 (parts count from 0)");
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let (i, n) = (
        i.trim().parse::<u32>().map_err(|_| bad())?,
        n.trim().parse::<u32>().map_err(|_| bad())?,
    );
    Part::new(i, n).ok_or_else(bad)
}

/// FNV-1a, 64 bits: stable across Rust versions and machines (the parts of one render may be
/// made by different processes on different hosts).
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    /// A field: its length first, so that ("ab", "c") and ("a", "bc") differ.
    fn field(&mut self, bytes: &[u8]) {
        self.write(&(bytes.len() as u64).to_le_bytes());
        self.write(bytes);
    }
}

/// The FNV-1a hash of `fields` (each prefixed by its length), in hex.
pub fn fnv_hex(fields: &[Vec<u8>]) -> String {
    let mut h = Fnv::new();
    for f in fields {
        h.field(f);
    }
    format!("{:016x}", h.0)
}

/// The scene's content hash: its file, the overrides it was loaded with, and every file it read
/// (meshes), byte for byte. Two renders with the same hash render the same scene.
pub fn scene_hash(scene: &Scene, overrides: &[String]) -> FotonResult<String> {
    let mut h = Fnv::new();
    let read = |path: &Path| std::fs::read(path).map_err(|e| Error::io(path, e));
    h.field(&read(scene.file())?);
    h.write(&(overrides.len() as u64).to_le_bytes());
    for o in overrides {
        h.field(o.as_bytes());
    }
    for source in scene.sources() {
        h.field(&read(source)?);
    }
    Ok(format!("{:016x}", h.0))
}

/// UTF-8 as the bytes of an EXR text attribute (which holds bytes).
fn text(s: &str) -> Text {
    Text::from_slice_unchecked(s.as_bytes())
}

fn exr_error(path: &Path, e: exr::error::Error) -> Error {
    Error::io(path, format!("cannot read the part: {e}"))
}

/// Writes `film` (a part, or a whole render) as a part file, atomically, with `extra` header
/// attributes besides those of `info`.
pub fn write_part(
    path: &Path,
    film: &Film,
    info: &PartInfo,
    extra: &[(&str, String)],
) -> FotonResult<()> {
    if format_of(path)? != ImageFormat::Exr {
        return Err(Error::io(
            path,
            "a part holds exact sums, which only EXR can store: name the output .exr",
        ));
    }
    let pixels = film.pixels();
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::with_capacity(16);
    for (c, name) in CHANNELS.iter().enumerate() {
        let mean = pixels.iter().map(|p| p[c]).collect();
        channels.push(AnyChannel::new(*name, FlatSamples::F32(mean)));
        for word in 0..4 {
            let words = sum_words(film.sums(), c, word);
            channels.push(AnyChannel::new(
                format!("sum.{name}.{word}").as_str(),
                words,
            ));
        }
    }
    for (c, name) in CHANNELS.iter().enumerate() {
        if film.splats().is_empty() {
            break;
        }
        for word in 0..4 {
            let words = sum_words(film.splats(), c, word);
            channels.push(AnyChannel::new(
                format!("splat.{name}.{word}").as_str(),
                words,
            ));
        }
    }
    channels.push(AnyChannel::new(
        "N",
        FlatSamples::U32(film.counts().to_vec()),
    ));
    let layer = Layer::new(
        (film.width as usize, film.height as usize),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let mut image = Image::from_layer(layer);
    for (key, value) in info.attributes().iter().chain(extra) {
        image
            .attributes
            .other
            .insert(text(key), AttributeValue::Text(text(value)));
    }
    write_atomic_with(path, |tmp| {
        image
            .write()
            .to_file(tmp)
            .map_err(|e| std::io::Error::other(e.to_string()))
    })
}

/// Word `word` (0: the least significant) of colour channel `c` of each of `sums`.
fn sum_words(sums: &[RadianceSum], c: usize, word: u32) -> FlatSamples {
    FlatSamples::U32(
        sums.iter()
            .map(|s| (s.0[c] >> (32 * word)) as u32)
            .collect(),
    )
}

/// The text attributes of an EXR's header and its size.
fn read_header(path: &Path) -> FotonResult<(BTreeMap<String, String>, (usize, usize))> {
    let meta = exr::meta::MetaData::read_from_file(path, true).map_err(|e| exr_error(path, e))?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| Error::io(path, "an EXR without any image"))?;
    // Custom attributes come back as the layer's, whichever struct wrote them.
    let attributes = header
        .own_attributes
        .other
        .iter()
        .chain(&header.shared_attributes.other)
        .filter_map(|(key, value)| match value {
            AttributeValue::Text(t) => Some((
                String::from_utf8_lossy(key.bytes()).into_owned(),
                String::from_utf8_lossy(t.bytes()).into_owned(),
            )),
            _ => None,
        })
        .collect();
    Ok((attributes, (header.layer_size.0, header.layer_size.1)))
}

/// Reads the header of a part file: what [`PartInfo`] holds, and every text attribute (the
/// extra ones a sweep's cell adds too).
pub fn read_part_header(path: &Path) -> FotonResult<(PartInfo, BTreeMap<String, String>)> {
    let (attributes, size) = read_header(path)?;
    let info = PartInfo::from_attributes(path, size, |key| attributes.get(key).cloned())?;
    Ok((info, attributes))
}

/// Reads the header of a part file.
pub fn read_part_info(path: &Path) -> FotonResult<PartInfo> {
    Ok(read_part_header(path)?.0)
}

/// Reads a part file's sums and counts.
pub fn read_part_film(path: &Path, info: &PartInfo) -> FotonResult<Film> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .pedantic()
        .from_file(path)
        .map_err(|e| exr_error(path, e))?;
    let layer = &image.layer_data;
    let n = info.width as usize * info.height as usize;
    let channel = |name: &str| -> FotonResult<&Vec<u32>> {
        let found = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.bytes() == name.as_bytes())
            .ok_or_else(|| Error::io(path, format!("damaged part: no channel {name}")))?;
        match &found.sample_data {
            FlatSamples::U32(v) if v.len() == n => Ok(v),
            _ => Err(Error::io(
                path,
                format!("damaged part: channel {name} is not {n} u32 values"),
            )),
        }
    };
    let mut sums = vec![RadianceSum::ZERO; n];
    for (c, name) in CHANNELS.iter().enumerate() {
        for word in 0..4 {
            let words = channel(&format!("sum.{name}.{word}"))?;
            for (s, &w) in sums.iter_mut().zip(words) {
                s.0[c] |= ((w as u128) << (32 * word)) as i128;
            }
        }
    }
    let counts = channel("N")?.clone();
    let has_splats = layer
        .channel_data
        .list
        .iter()
        .any(|c| c.name.bytes().starts_with(b"splat."));
    let mut splats = Vec::new();
    if has_splats {
        splats = vec![RadianceSum::ZERO; n];
        for (c, name) in CHANNELS.iter().enumerate() {
            for word in 0..4 {
                let words = channel(&format!("splat.{name}.{word}"))?;
                for (s, &w) in splats.iter_mut().zip(words) {
                    s.0[c] |= ((w as u128) << (32 * word)) as i128;
                }
            }
        }
    }
    Film::from_sums(info.width, info.height, sums, counts, splats)
        .ok_or_else(|| Error::io(path, "damaged part: channels of the wrong size"))
}
