//! Mitsuba's `serialized` meshes (versions 3 and 4 of the format, which Mitsuba 0.4 to 0.6
//! write and Mitsuba 3 reads, and version 5, which Mitsuba 3 writes since 2026): indexed
//! triangle meshes, each a zlib stream behind a short uncompressed header, several to a file,
//! with a dictionary of where each starts at the end.
//!
//! The layout, all little-endian, as Mitsuba's documentation of the `serialized` plugin gives it:
//!
//! | bytes              | content                                                          |
//! |--------------------|------------------------------------------------------------------|
//! | u16                | format identifier 0x041C                                         |
//! | u16                | version: 3 or 4 (5 below)                                        |
//! | zlib stream:       |                                                                  |
//! | u32                | flags: 0x1 vertex normals, 0x2 texture coordinates, 0x8 vertex colours, 0x10 face normals, 0x1000 single, 0x2000 double precision |
//! | bytes, NUL         | the shape's name (version 4 only)                                |
//! | u64, u64           | vertex count V, triangle count F                                 |
//! | 3V floats          | positions; then 3V normals, 2V texture coordinates, 3V colours as the flags say (f32, or f64 with 0x2000) |
//! | 3F u32             | vertex indices of the triangles                                  |
//!
//! Version 5 stores Mitsuba 3's packed records instead: after the flags (low four bits the
//! record layout: 0x1 normals, 0x2 tangents, 0x4 texture coordinates; 0x10 face normals;
//! 0x1000 always set) the name (u32 length, bytes), the vertex, triangle, surface point and
//! normal group counts (u64 each), 8 f32 per vertex (position, normal, or with tangents an
//! encoded frame, uv), 4 u32 per triangle (three indices and a BSDF index), then index maps
//! and attributes, which foton does not need.
//!
//! Further meshes follow, each with its own header and zlib stream; the file ends with the
//! offset of each mesh (u64 from version 4, u32 in version 3) and their count (u32). Mesh 0
//! is read from the start of the file, any other through the dictionary, as Mitsuba does.
//!
//! Vertex colours are read past: Mitsuba 3 does the same, and foton has no texture that reads
//! them. The face-normals flag of versions 3 and 4 is not honoured: Mitsuba 0.6's and 3's
//! `serialized` plugins take `face_normals` from the scene only; version 5's is, when the
//! scene does not say. A version 5 frame encoded with tangents is not decoded: the normals are
//! then computed. Errors are plain text; the caller adds the file and the scene key.

use super::raw::RawMesh;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::io::Read;

/// The format identifier, the file's first two bytes.
pub const MAGIC: u16 = 0x041C;

const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const DOUBLE_PRECISION: u32 = 0x2000;

/// Whether `data` starts as a serialized mesh does (for files whose name does not say).
pub fn is_serialized(data: &[u8]) -> bool {
    data.len() >= 2 && u16::from_le_bytes([data[0], data[1]]) == MAGIC
}

/// Mesh number `shape_index` of the serialized file `data`, with its normals and texture
/// coordinates if the file stores them (indexed like the positions).
pub fn parse(data: &[u8], shape_index: u32) -> Result<RawMesh, String> {
    let version = header(data, 0)?;
    let start = if shape_index == 0 {
        0
    } else {
        let start = offset(data, version, shape_index)?;
        match header(data, start) {
            Ok(v) if v == version => {}
            _ => {
                return Err(format!(
                    "corrupt file: its dictionary says mesh {shape_index} starts at byte {start}, where no mesh of version {version} starts"
                ));
            }
        }
        start
    };
    let mut bytes = Vec::new();
    flate2::read::ZlibDecoder::new(&data[start + 4..])
        .read_to_end(&mut bytes)
        .map_err(|e| format!("mesh {shape_index}: corrupt compressed data: {e}"))?;
    if version == 5 {
        mesh_v5(&bytes)
    } else {
        mesh(&bytes, version)
    }
    .map_err(|e| format!("mesh {shape_index}: {e}"))
}

/// The version of the mesh whose header starts at byte `at`.
fn header(data: &[u8], at: usize) -> Result<u16, String> {
    let Some(h) = data.get(at..at.saturating_add(4)) else {
        return Err(format!(
            "not a Mitsuba serialized mesh: {} bytes, too short for a header",
            data.len()
        ));
    };
    let format = u16::from_le_bytes([h[0], h[1]]);
    let version = u16::from_le_bytes([h[2], h[3]]);
    if format != MAGIC {
        return Err(format!(
            "not a Mitsuba serialized mesh: it starts with 0x{format:04X}, expected 0x{MAGIC:04X}"
        ));
    }
    match version {
        3..=5 => Ok(version),
        _ => Err(format!(
            "serialized mesh version {version}; foton reads versions 3 to 5 (those of Mitsuba 0.4 to 0.6 and 3)"
        )),
    }
}

/// Where mesh `index` starts, from the dictionary at the end of the file.
fn offset(data: &[u8], version: u16, index: u32) -> Result<usize, String> {
    let n = data.len();
    let corrupt = || "corrupt file: its dictionary of meshes runs past its start".to_string();
    let count = u32::from_le_bytes(
        data[n.checked_sub(4).ok_or_else(corrupt)?..]
            .try_into()
            .unwrap(),
    );
    if index >= count {
        return Err(format!(
            "shape_index {index} is out of range: the file holds {count} mesh{} (0 to {})",
            if count == 1 { "" } else { "es" },
            count.saturating_sub(1)
        ));
    }
    let from_end = (count - index) as usize;
    let start = if version >= 4 {
        let at = n.checked_sub(4 + 8 * from_end).ok_or_else(corrupt)?;
        u64::from_le_bytes(data[at..at + 8].try_into().unwrap())
    } else {
        let at = n.checked_sub(4 * (from_end + 1)).ok_or_else(corrupt)?;
        u32::from_le_bytes(data[at..at + 4].try_into().unwrap()) as u64
    };
    usize::try_from(start)
        .ok()
        .filter(|&s| s < n)
        .ok_or_else(|| {
            format!("corrupt file: its dictionary says mesh {index} starts at byte {start}, past its end ({n} bytes)")
        })
}

/// Reads the decompressed stream of one mesh.
struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    /// `count` items of `size` bytes: `what` names them in the message if the data ends first.
    fn take(&mut self, count: u64, size: usize, what: &str) -> Result<&'a [u8], String> {
        let left = self.data.len() - self.pos;
        let wanted = usize::try_from(count)
            .ok()
            .and_then(|c| c.checked_mul(size))
            .filter(|&w| w <= left)
            .ok_or_else(|| {
                format!(
                    "truncated: {count} {what} need {} bytes, only {left} are left",
                    count as u128 * size as u128
                )
            })?;
        let out = &self.data[self.pos..self.pos + wanted];
        self.pos += wanted;
        Ok(out)
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(
            self.take(1, 4, what)?.try_into().unwrap(),
        ))
    }

    fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.take(1, 8, what)?.try_into().unwrap(),
        ))
    }

    /// A NUL-terminated string (version 4's shape name).
    fn c_string(&mut self) -> Result<(), String> {
        let rest = &self.data[self.pos..];
        let len = rest
            .iter()
            .position(|&c| c == 0)
            .ok_or("truncated: the shape's name has no terminating NUL")?;
        self.pos += len + 1;
        Ok(())
    }
}

/// Above this many items, arrays are converted on every thread.
const PARALLEL: usize = 1 << 14;

/// `n`-component vectors of f32 or f64, as f32.
fn floats<T: Send, const N: usize>(
    bytes: &[u8],
    double: bool,
    make: impl Fn([f32; N]) -> T + Sync + Send,
) -> Vec<T> {
    let size = if double { 8 } else { 4 };
    let item = |c: &[u8]| {
        let mut v = [0.0f32; N];
        for (k, x) in v.iter_mut().enumerate() {
            let b = &c[k * size..(k + 1) * size];
            *x = if double {
                f64::from_le_bytes(b.try_into().unwrap()) as f32
            } else {
                f32::from_le_bytes(b.try_into().unwrap())
            };
        }
        make(v)
    };
    if bytes.len() / (N * size) > PARALLEL {
        bytes.par_chunks_exact(N * size).map(item).collect()
    } else {
        bytes.chunks_exact(N * size).map(item).collect()
    }
}

fn mesh(data: &[u8], version: u16) -> Result<RawMesh, String> {
    let mut c = Cursor { data, pos: 0 };
    let flags = c.u32("flag words")?;
    if version == 4 {
        c.c_string()?;
    }
    let vertices = c.u64("vertex counts")?;
    let faces = c.u64("triangle counts")?;
    let double = flags & DOUBLE_PRECISION != 0;
    let scalar = if double { 8 } else { 4 };
    let positions = c.take(vertices, 3 * scalar, "vertex positions")?;
    let normals = if flags & HAS_NORMALS != 0 {
        Some(c.take(vertices, 3 * scalar, "vertex normals")?)
    } else {
        None
    };
    let uvs = if flags & HAS_TEXCOORDS != 0 {
        Some(c.take(vertices, 2 * scalar, "texture coordinates")?)
    } else {
        None
    };
    if flags & HAS_COLORS != 0 {
        c.take(vertices, 3 * scalar, "vertex colours")?;
    }
    let indices = c.take(faces, 12, "triangles")?;
    let triangles: Vec<[u32; 3]> = {
        let item = |t: &[u8]| {
            [0, 1, 2].map(|k| u32::from_le_bytes(t[4 * k..4 * k + 4].try_into().unwrap()))
        };
        if faces as usize > PARALLEL {
            indices.par_chunks_exact(12).map(item).collect()
        } else {
            indices.chunks_exact(12).map(item).collect()
        }
    };
    let mut raw = RawMesh {
        positions: floats(positions, double, Vec3::from_array),
        ..RawMesh::default()
    };
    if let Some(n) = normals {
        raw.normals = floats(n, double, Vec3::from_array);
        raw.normal_triangles = triangles.clone();
    }
    if let Some(t) = uvs {
        raw.uvs = floats(t, double, Vec2::from_array);
        raw.uv_triangles = triangles.clone();
    }
    raw.triangles = triangles;
    Ok(raw)
}

/// Version 5's vertex records: 8 f32 lanes, and its face records: 4 u32.
const V5_VERTEX: usize = 32;
const V5_FACE: usize = 16;

fn mesh_v5(data: &[u8]) -> Result<RawMesh, String> {
    let mut c = Cursor { data, pos: 0 };
    let flags = c.u32("flag words")?;
    if flags & 0x1000 == 0 {
        return Err(
            "a version 5 mesh without the single-precision flag (Mitsuba writes it always)".into(),
        );
    }
    let name = c.u32("name lengths")?;
    c.take(name as u64, 1, "bytes of the name")?;
    let vertices = c.u64("vertex counts")?;
    let faces = c.u64("triangle counts")?;
    let points = c.u64("surface point counts")?;
    let groups = c.u64("normal group counts")?;
    let (normals, tangents, uvs) = (flags & 1 != 0, flags & 2 != 0, flags & 4 != 0);
    if points > vertices || groups > vertices || (tangents && !normals) {
        return Err(format!(
            "invalid header: {vertices} vertices, {points} surface points, {groups} normal groups, layout 0x{:x}",
            flags & 0xF
        ));
    }
    let records = c.take(vertices, V5_VERTEX, "vertex records")?;
    let face_records = c.take(faces, V5_FACE, "triangles")?;
    let lanes = |r: &[u8], from: usize| {
        let lane = |k: usize| f32::from_le_bytes(r[4 * k..4 * k + 4].try_into().unwrap());
        [lane(from), lane(from + 1), lane(from + 2)]
    };
    let parallel = vertices as usize > PARALLEL;
    let map_records = |f: &(dyn Fn(&[u8]) -> [f32; 3] + Sync)| -> Vec<[f32; 3]> {
        if parallel {
            records.par_chunks_exact(V5_VERTEX).map(f).collect()
        } else {
            records.chunks_exact(V5_VERTEX).map(f).collect()
        }
    };
    let triangles: Vec<[u32; 3]> = {
        let item = |t: &[u8]| {
            [0, 1, 2].map(|k| u32::from_le_bytes(t[4 * k..4 * k + 4].try_into().unwrap()))
        };
        if faces as usize > PARALLEL {
            face_records.par_chunks_exact(V5_FACE).map(item).collect()
        } else {
            face_records.chunks_exact(V5_FACE).map(item).collect()
        }
    };
    let mut raw = RawMesh {
        positions: map_records(&|r| lanes(r, 0))
            .into_iter()
            .map(Vec3::from_array)
            .collect(),
        face_normals: flags & 0x10 != 0,
        ..RawMesh::default()
    };
    if normals && !tangents {
        raw.normals = map_records(&|r| lanes(r, 3))
            .into_iter()
            .map(Vec3::from_array)
            .collect();
        raw.normal_triangles = triangles.clone();
    }
    if uvs {
        raw.uvs = map_records(&|r| lanes(r, 5))
            .into_iter()
            .map(|l| Vec2::new(l[1], l[2]))
            .collect();
        raw.uv_triangles = triangles.clone();
    }
    raw.triangles = triangles;
    Ok(raw)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use flate2::Compression;
    use flate2::write::ZlibEncoder;
    use std::io::Write;

    /// A mesh to write: positions, optional normals and texture coordinates, triangles.
    #[derive(Clone, Debug, Default)]
    pub(crate) struct Mesh {
        pub positions: Vec<[f64; 3]>,
        pub normals: Option<Vec<[f64; 3]>>,
        pub uvs: Option<Vec<[f64; 2]>>,
        pub colors: bool,
        pub triangles: Vec<[u32; 3]>,
    }

    /// A serialized file of `meshes` (format `version`, f64 or f32), written as Mitsuba
    /// writes one: an independent encoder, so that the reader is checked against the
    /// documentation of the format rather than against itself.
    pub(crate) fn encode(meshes: &[Mesh], version: u16, double: bool) -> Vec<u8> {
        let mut file = Vec::new();
        let mut offsets = Vec::new();
        for (i, m) in meshes.iter().enumerate() {
            offsets.push(file.len() as u64);
            file.extend(MAGIC.to_le_bytes());
            file.extend(version.to_le_bytes());
            if version == 5 {
                file.extend(zlib(&v5_stream(m, i, 0)));
                continue;
            }
            let mut s = Vec::new();
            let mut flags = if double { 0x2000u32 } else { 0x1000 };
            flags |= if m.normals.is_some() { 1 } else { 0 };
            flags |= if m.uvs.is_some() { 2 } else { 0 };
            flags |= if m.colors { 8 } else { 0 };
            s.extend(flags.to_le_bytes());
            if version == 4 {
                s.extend(format!("mesh{i}").bytes());
                s.push(0);
            }
            s.extend((m.positions.len() as u64).to_le_bytes());
            s.extend((m.triangles.len() as u64).to_le_bytes());
            let mut put = |xs: &[f64]| {
                for &x in xs {
                    if double {
                        s.extend(x.to_le_bytes());
                    } else {
                        s.extend((x as f32).to_le_bytes());
                    }
                }
            };
            put(m.positions.as_flattened());
            if let Some(n) = &m.normals {
                put(n.as_flattened());
            }
            if let Some(t) = &m.uvs {
                put(t.as_flattened());
            }
            if m.colors {
                put(&vec![0.5; 3 * m.positions.len()]);
            }
            for t in &m.triangles {
                for i in t {
                    s.extend(i.to_le_bytes());
                }
            }
            file.extend(zlib(&s));
        }
        for o in &offsets {
            if version >= 4 {
                file.extend(o.to_le_bytes());
            } else {
                file.extend((*o as u32).to_le_bytes());
            }
        }
        file.extend((meshes.len() as u32).to_le_bytes());
        file
    }

    fn zlib(data: &[u8]) -> Vec<u8> {
        let mut z = ZlibEncoder::new(Vec::new(), Compression::default());
        z.write_all(data).unwrap();
        z.finish().unwrap()
    }

    /// The zlib-compressed part of a version 5 mesh (Mitsuba 3's `Mesh::write_serialized`),
    /// with `extra` flag bits (0x10 face normals, 0x2 tangents).
    fn v5_stream(m: &Mesh, i: usize, extra: u32) -> Vec<u8> {
        let mut s = Vec::new();
        let layout = u32::from(m.normals.is_some()) | (4 * u32::from(m.uvs.is_some()));
        s.extend((0x1000 | layout | extra).to_le_bytes());
        let name = format!("mesh{i}");
        s.extend((name.len() as u32).to_le_bytes());
        s.extend(name.bytes());
        for n in [m.positions.len(), m.triangles.len(), 0, 0] {
            s.extend((n as u64).to_le_bytes());
        }
        for (v, p) in m.positions.iter().enumerate() {
            let n = m.normals.as_ref().map_or([0.0; 3], |n| n[v]);
            let t = m.uvs.as_ref().map_or([0.0; 2], |t| t[v]);
            for x in p.iter().chain(&n).chain(&t) {
                s.extend((*x as f32).to_le_bytes());
            }
        }
        for t in &m.triangles {
            for i in t.iter().chain(&[0]) {
                s.extend(i.to_le_bytes());
            }
        }
        // No attributes.
        s.extend(0u32.to_le_bytes());
        s
    }

    /// A square of two triangles, z = `z`, with or without normals and texture coordinates.
    pub(crate) fn square(z: f64, normals: bool, uvs: bool) -> Mesh {
        Mesh {
            positions: vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]],
            normals: normals.then(|| vec![[0.0, 0.0, 1.0]; 4]),
            uvs: uvs.then(|| vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
            colors: false,
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    /// A fan of `n` triangles around the origin, with normals tilted by a third of a degree
    /// (values that single precision rounds).
    fn fan(n: u32) -> Mesh {
        let mut m = Mesh {
            positions: vec![[0.0, 0.0, 0.1]],
            normals: Some(vec![[0.0, 0.0, 1.0]]),
            uvs: None,
            colors: true,
            triangles: Vec::new(),
        };
        for k in 0..n {
            let a = k as f64 / n as f64 * std::f64::consts::TAU;
            m.positions.push([a.cos(), a.sin(), 0.0]);
            m.normals
                .as_mut()
                .unwrap()
                .push([a.cos() / 3.0, a.sin() / 3.0, 1.0]);
            m.triangles.push([0, 1 + k, 1 + (k + 1) % n]);
        }
        m
    }

    fn check(raw: &RawMesh, m: &Mesh) {
        // Written as f32 or as f64, a value reads back as the f32 nearest to it.
        let f = |x: f64| x as f32;
        let v3 = |p: &[f64; 3]| Vec3::new(f(p[0]), f(p[1]), f(p[2]));
        assert_eq!(
            raw.positions,
            m.positions.iter().map(v3).collect::<Vec<_>>()
        );
        assert_eq!(raw.triangles, m.triangles);
        match &m.normals {
            Some(n) => {
                assert_eq!(raw.normals, n.iter().map(v3).collect::<Vec<_>>());
                assert_eq!(raw.normal_triangles, m.triangles);
            }
            None => assert!(raw.normals.is_empty() && raw.normal_triangles.is_empty()),
        }
        match &m.uvs {
            Some(t) => {
                let uv: Vec<Vec2> = t.iter().map(|t| Vec2::new(f(t[0]), f(t[1]))).collect();
                assert_eq!(raw.uvs, uv);
                assert_eq!(raw.uv_triangles, m.triangles);
            }
            None => assert!(raw.uvs.is_empty() && raw.uv_triangles.is_empty()),
        }
    }

    #[test]
    fn every_mesh_of_a_file_decodes_in_every_version_and_precision() {
        let meshes = vec![
            square(0.0, false, false),
            square(1.0, true, false),
            fan(7),
            square(2.5, false, true),
            square(-3.0, true, true),
            fan(40_000), // above PARALLEL: the parallel conversion
        ];
        for (version, double) in [(3, false), (3, true), (4, false), (4, true), (5, false)] {
            let file = encode(&meshes, version, double);
            for (i, m) in meshes.iter().enumerate() {
                let raw = parse(&file, i as u32)
                    .unwrap_or_else(|e| panic!("v{version} double {double} mesh {i}: {e}"));
                check(&raw, m);
            }
            let e = parse(&file, 6).unwrap_err();
            assert!(
                e.contains("shape_index 6 is out of range") && e.contains("6 meshes (0 to 5)"),
                "{e}"
            );
        }
    }

    #[test]
    fn a_double_precision_value_is_rounded_once() {
        let mut m = square(0.0, false, false);
        m.positions[0] = [0.1, 1.0 / 3.0, 1e-40];
        let raw = parse(&encode(&[m], 4, true), 0).unwrap();
        assert_eq!(raw.positions[0], Vec3::new(0.1, 1.0 / 3.0, 1e-40));
    }

    #[test]
    fn a_truncated_or_corrupt_file_is_an_error_never_a_panic() {
        let meshes = vec![square(0.0, true, true), fan(9)];
        for version in [3, 4, 5] {
            let file = encode(&meshes, version, false);
            // Mesh 1 starts where mesh 0's stream ends.
            let end0 =
                encode(&meshes[..1], version, false).len() - if version >= 4 { 12 } else { 8 };
            // Every prefix of the file: mesh 0 decodes whole once its stream is complete, and
            // is an error before; mesh 1 is an error or (by a chance of the cut) some mesh.
            for len in 0..file.len() {
                match parse(&file[..len], 0) {
                    Ok(raw) => {
                        assert!(len >= end0, "mesh 0 decoded from {len} of {end0} bytes");
                        check(&raw, &meshes[0]);
                    }
                    Err(e) => assert!(len < end0, "mesh 0 refused from {len} bytes: {e}"),
                }
                let _ = parse(&file[..len], 1);
            }
            // Every byte flipped in turn.
            for i in 0..file.len() {
                let mut bad = file.clone();
                bad[i] ^= 0x5a;
                for index in 0..3 {
                    let _ = parse(&bad, index);
                }
            }
        }
        let file = encode(&meshes, 4, false);
        let e = parse(&file[..2], 0).unwrap_err();
        assert!(e.contains("too short for a header"), "{e}");
        let e = parse(b"ply\nformat ascii 1.0\n", 0).unwrap_err();
        assert!(e.contains("not a Mitsuba serialized mesh"), "{e}");
        let e = parse(&file[..40], 0).unwrap_err();
        assert!(e.contains("mesh 0: "), "{e}");
    }

    /// Mutated files, never a panic: bytes changed, inserted or removed, the file cut, in the
    /// file as stored or (to reach the mesh reader past the inflater) in the first mesh's
    /// stream before compression; what decodes then through the shared mesh code. 20,000 by
    /// default; `FOTON_FUZZ_SERIALIZED=N` runs N (a million took 23 s on one 2-vCPU machine).
    #[test]
    fn mutated_files_are_errors_or_meshes_never_panics() {
        let n: usize = std::env::var("FOTON_FUZZ_SERIALIZED")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(20_000);
        let meshes = [square(0.0, true, true), fan(5), square(1.0, false, true)];
        // (version, the file, its first mesh's stream uncompressed)
        let seeds: Vec<(u16, Vec<u8>, Vec<u8>)> = [(3, false), (4, true), (5, false)]
            .iter()
            .map(|&(v, d)| {
                let file = encode(&meshes, v, d);
                let mut stream = Vec::new();
                flate2::read::ZlibDecoder::new(&file[4..])
                    .read_to_end(&mut stream)
                    .unwrap();
                (v, file, stream)
            })
            .collect();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |m: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % m.max(1) as u64) as usize
        };
        let mut outcomes = [0usize; 2];
        for _ in 0..n {
            let (version, file, stream) = &seeds[next(seeds.len())];
            let inner = next(2) == 0;
            let mut f = if inner { stream.clone() } else { file.clone() };
            for _ in 0..1 + next(4) {
                if f.is_empty() {
                    break;
                }
                let at = next(f.len());
                match next(5) {
                    0 => f[at] ^= 1 << next(8),
                    1 => f[at] = next(256) as u8,
                    2 => f.insert(at, next(256) as u8),
                    3 => {
                        f.remove(at);
                    }
                    _ => f.truncate(at),
                }
            }
            if inner {
                let mut file = vec![0x1C, 0x04, *version as u8, 0];
                file.extend(zlib(&f));
                f = file;
            }
            let result = parse(&f, if inner { 0 } else { next(4) as u32 });
            outcomes[result.is_ok() as usize] += 1;
            // What decodes goes on through the shared mesh code, garbage values and all.
            if let Ok(raw) = result {
                let options = super::super::MeshOptions {
                    face_normals: next(2) == 0,
                    flip_tex_coords: false,
                    flip_normals: next(2) == 0,
                    compute_normals: true,
                };
                let crease = (next(2) == 0 && !options.face_normals).then_some(30.0);
                let _ = super::super::triangles(raw, glam::Mat4::IDENTITY, options, crease);
            }
        }
        // Both outcomes occur: the mutations reach past the header checks.
        assert!(outcomes[0] > 0 && outcomes[1] > 0, "{outcomes:?}");
    }

    #[test]
    fn counts_larger_than_the_data_are_an_error_not_an_allocation() {
        // A header that claims 2^62 vertices: the reader must compare with what the stream
        // holds before it allocates anything.
        let mut s = Vec::new();
        s.extend(0x1000u32.to_le_bytes());
        s.extend((1u64 << 62).to_le_bytes());
        s.extend(1u64.to_le_bytes());
        let mut z = ZlibEncoder::new(Vec::new(), Compression::default());
        z.write_all(&s).unwrap();
        let mut file = vec![0x1C, 0x04, 3, 0];
        file.extend(z.finish().unwrap());
        let e = parse(&file, 0).unwrap_err();
        assert!(
            e.contains("truncated") && e.contains("vertex positions"),
            "{e}"
        );
    }

    #[test]
    fn version_5_flags_face_normals_tangents_and_bad_headers() {
        let m = square(0.0, true, true);
        let one = |stream: Vec<u8>| {
            let mut file = vec![0x1C, 0x04, 5, 0];
            file.extend(zlib(&stream));
            parse(&file, 0)
        };
        let raw = one(v5_stream(&m, 0, 0)).unwrap();
        assert!(!raw.face_normals && raw.normals.len() == 4 && raw.uvs.len() == 4);
        assert!(one(v5_stream(&m, 0, 0x10)).unwrap().face_normals);
        // An encoded tangent frame is not a normal: the normals are left to be computed.
        let raw = one(v5_stream(&m, 0, 0x2)).unwrap();
        assert!(raw.normals.is_empty() && raw.normal_triangles.is_empty());
        assert_eq!(raw.uvs[2], Vec2::ONE);
        // Tangents without normals, and more surface points than vertices.
        let e = one(v5_stream(&square(0.0, false, false), 0, 0x2)).unwrap_err();
        assert!(e.contains("invalid header"), "{e}");
        let mut s = v5_stream(&m, 0, 0);
        // flags, name length, "mesh0", vertex and triangle counts: then the point count.
        let points = 4 + 4 + 5 + 16;
        s[points..points + 8].copy_from_slice(&5u64.to_le_bytes());
        let e = one(s).unwrap_err();
        assert!(e.contains("5 surface points"), "{e}");
        let mut s = v5_stream(&m, 0, 0);
        s[1] = 0;
        let e = one(s).unwrap_err();
        assert!(e.contains("single-precision"), "{e}");
    }

    #[test]
    fn other_versions_and_formats_are_named() {
        let mut file = encode(&[square(0.0, false, false)], 4, false);
        file[2] = 6;
        let e = parse(&file, 0).unwrap_err();
        assert!(
            e.contains("version 6") && e.contains("versions 3 to 5"),
            "{e}"
        );
        assert!(is_serialized(&file) && !is_serialized(b"ply") && !is_serialized(b""));
    }
}
