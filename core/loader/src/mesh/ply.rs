//! Stanford PLY meshes (ascii, binary little- and big-endian): vertex positions and faces.
//!
//! `x y z` (and normals and texture coordinates) of the vertices and the `vertex_indices` (or
//! `vertex_index`) list of the faces are read; every other property and element is read past,
//! but for the mesh attribute a scene asks for ([`attribute`], a pass of its own). Polygons are fan-triangulated,
//! the same way tobj triangulates OBJ faces, so that an OBJ and a PLY of one model give the
//! same triangles. Errors are plain text; the caller adds the file and the scene key.

use super::raw::RawMesh;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// Above this many records, binary records of a fixed size are decoded on every thread.
const PARALLEL: usize = 1 << 14;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// The value at the start of `b` (at least `size()` bytes). f64 holds every value of every
    /// type exactly, so a float read through it is the float that was written.
    #[inline]
    fn read(self, b: &[u8], big: bool) -> f64 {
        macro_rules! get {
            ($t:ty, $n:expr) => {{
                let a: [u8; $n] = b[..$n].try_into().unwrap();
                if big {
                    <$t>::from_be_bytes(a) as f64
                } else {
                    <$t>::from_le_bytes(a) as f64
                }
            }};
        }
        match self {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => get!(i16, 2),
            Scalar::U16 => get!(u16, 2),
            Scalar::I32 => get!(i32, 4),
            Scalar::U32 => get!(u32, 4),
            Scalar::F32 => get!(f32, 4),
            Scalar::F64 => get!(f64, 8),
        }
    }

    /// An ascii token of this type. Floats are parsed at their own precision (a `float` as
    /// f32 directly: through f64 it could round twice).
    fn parse_value(self, token: &str) -> Option<f64> {
        match self {
            Scalar::F32 => token.parse::<f32>().ok().map(f64::from),
            Scalar::F64 => token.parse::<f64>().ok(),
            Scalar::I8 => token.parse::<i8>().ok().map(f64::from),
            Scalar::U8 => token.parse::<u8>().ok().map(f64::from),
            Scalar::I16 => token.parse::<i16>().ok().map(f64::from),
            Scalar::U16 => token.parse::<u16>().ok().map(f64::from),
            Scalar::I32 => token.parse::<i32>().ok().map(f64::from),
            Scalar::U32 => token.parse::<u32>().ok().map(f64::from),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    Binary { big: bool },
}

#[derive(Debug)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

impl Element {
    /// Bytes per record in binary, if every property is a scalar.
    fn fixed_size(&self) -> Option<usize> {
        self.properties
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(t) => Some(t.size()),
                Kind::List { .. } => None,
            })
            .sum()
    }

    /// What one record is called in messages.
    fn noun(&self) -> String {
        match self.name.as_str() {
            "vertex" => "vertices".into(),
            "face" => "faces".into(),
            other => format!("`{other}` elements"),
        }
    }
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Where the data starts.
    body: usize,
}

fn parse_header(data: &[u8]) -> Result<Header, String> {
    const END: &[u8] = b"end_header";
    let mut pos = 0;
    let mut next_line = || -> Option<&[u8]> {
        if pos >= data.len() {
            return None;
        }
        let rest = &data[pos..];
        let len = rest.iter().position(|&c| c == b'\n');
        let line = &rest[..len.unwrap_or(rest.len())];
        pos += len.map_or(rest.len(), |n| n + 1);
        Some(line.strip_suffix(b"\r").unwrap_or(line))
    };
    if next_line() != Some(b"ply") {
        return Err("not a PLY file: it does not start with a `ply` line".into());
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut number = 1;
    loop {
        let line = next_line().ok_or("bad PLY header: no `end_header` line")?;
        number += 1;
        let line = std::str::from_utf8(line)
            .map_err(|_| format!("bad PLY header: line {number} is not text"))?;
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        let bad = |what: &str| format!("bad PLY header, line {number} ({line:?}): {what}");
        match words.as_slice() {
            [] | ["comment" | "obj_info", ..] => {}
            [w] if w.as_bytes() == END => break,
            ["format", f, version] => {
                if *version != "1.0" {
                    return Err(bad("unsupported version; expected 1.0"));
                }
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Binary { big: false },
                    "binary_big_endian" => Format::Binary { big: true },
                    _ => {
                        return Err(bad(
                            "unknown format; expected ascii, binary_little_endian or binary_big_endian",
                        ));
                    }
                });
            }
            ["element", name, count] => {
                let count = count
                    .parse()
                    .map_err(|_| bad("the element count is not a non-negative integer"))?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", rest @ ..] => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| bad("a property before any element"))?;
                let ty = |name: &str| {
                    Scalar::parse(name).ok_or_else(|| {
                        bad(&format!("unknown type {name:?}; expected char, uchar, short, ushort, int, uint, float, double (or int8 ... float64)"))
                    })
                };
                let (kind, name) = match rest {
                    ["list", count, item, name] => {
                        let count = ty(count)?;
                        if !count.is_integer() {
                            return Err(bad("a list count must have an integer type"));
                        }
                        (
                            Kind::List {
                                count,
                                item: ty(item)?,
                            },
                            name,
                        )
                    }
                    [t, name] if *t != "list" => (Kind::Scalar(ty(t)?), name),
                    _ => {
                        return Err(bad(
                            "expected `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`",
                        ));
                    }
                };
                element.properties.push(Property {
                    name: name.to_string(),
                    kind,
                });
            }
            _ => {
                return Err(bad(
                    "expected format, element, property, comment or end_header",
                ));
            }
        }
    }
    let format = format.ok_or("bad PLY header: no `format` line")?;
    Ok(Header {
        format,
        elements,
        body: pos,
    })
}

/// Where the mesh's data is among the elements' properties.
struct Layout {
    vertex: usize,
    /// Per property of the vertex element: which of [`FIELDS`] it holds, if any.
    slots: Vec<Option<usize>>,
    has_normals: bool,
    has_uvs: bool,
    face: usize,
    indices: usize,
}

/// The vertex fields read: position, normal, texture coordinates (slots 0-2, 3-5, 6-7).
const FIELDS: usize = 8;

/// The names a vertex property may have for each field, as Mitsuba 3 reads them (texture
/// coordinates as `u`/`v`, `s`/`t` or `texture_u`/`texture_v`).
fn field_of(name: &str) -> Option<usize> {
    Some(match name {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        "nx" => 3,
        "ny" => 4,
        "nz" => 5,
        "u" | "s" | "texture_u" => 6,
        "v" | "t" | "texture_v" => 7,
        _ => return None,
    })
}

fn layout(elements: &[Element]) -> Result<Layout, String> {
    let find = |name: &str| elements.iter().position(|e| e.name == name);
    let vertex = find("vertex").ok_or("the PLY file has no `vertex` element")?;
    let props = &elements[vertex].properties;
    let mut slots = vec![None; props.len()];
    let mut seen = [false; FIELDS];
    for (p, property) in props.iter().enumerate() {
        let Some(f) = field_of(&property.name) else {
            continue;
        };
        if matches!(property.kind, Kind::List { .. }) {
            if f < 3 {
                return Err(format!(
                    "the vertex property `{}` is a list; expected a number",
                    property.name
                ));
            }
            continue;
        }
        if !seen[f] {
            seen[f] = true;
            slots[p] = Some(f);
        }
    }
    for (f, axis) in ["x", "y", "z"].iter().enumerate() {
        if !seen[f] {
            return Err(format!(
                "the `vertex` element has no `{axis}` property (vertices need x, y and z)"
            ));
        }
    }
    let face = find("face").ok_or("the PLY file has no `face` element (a point cloud?)")?;
    let props = &elements[face].properties;
    let indices = props
        .iter()
        .position(|p| p.name == "vertex_indices" || p.name == "vertex_index")
        .ok_or("the `face` element has no `vertex_indices` (or `vertex_index`) property")?;
    match props[indices].kind {
        Kind::List { item, .. } if item.is_integer() => {}
        _ => {
            return Err(format!(
                "the face property `{}` must be a list of integers",
                props[indices].name
            ));
        }
    }
    Ok(Layout {
        vertex,
        slots,
        has_normals: seen[3] && seen[4] && seen[5],
        has_uvs: seen[6] && seen[7],
        face,
        indices,
    })
}

/// Accumulates the positions and fan-triangulated faces as the elements are read.
struct Builder {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    triangles: Vec<[u32; 3]>,
    polygon: Vec<u32>,
}

impl Builder {
    /// A vertex is read: its fields in [`FIELDS`] order.
    fn vertex(&mut self, layout: &Layout, v: &[f32; FIELDS]) {
        self.positions.push(Vec3::new(v[0], v[1], v[2]));
        if layout.has_normals {
            self.normals.push(Vec3::new(v[3], v[4], v[5]));
        }
        if layout.has_uvs {
            self.uvs.push(Vec2::new(v[6], v[7]));
        }
    }

    /// Many vertices, decoded on every thread: their fields in [`FIELDS`] order.
    fn vertices(&mut self, layout: &Layout, all: &[[f32; FIELDS]]) {
        self.positions
            .par_extend(all.par_iter().map(|v| Vec3::new(v[0], v[1], v[2])));
        if layout.has_normals {
            self.normals
                .par_extend(all.par_iter().map(|v| Vec3::new(v[3], v[4], v[5])));
        }
        if layout.has_uvs {
            self.uvs
                .par_extend(all.par_iter().map(|v| Vec2::new(v[6], v[7])));
        }
    }

    /// Face `face` is done: `polygon` holds its indices.
    fn end_face(&mut self, face: usize) -> Result<(), String> {
        let p = &self.polygon;
        if p.len() < 3 {
            return Err(format!(
                "face {face} has {} vertex indices; a face needs at least 3",
                p.len()
            ));
        }
        for i in 1..p.len() - 1 {
            self.triangles.push([p[0], p[i], p[i + 1]]);
        }
        self.polygon.clear();
        Ok(())
    }

    fn index(&mut self, face: usize, value: f64) -> Result<(), String> {
        // Negative indices cannot be u32; the range check against the vertex count is the
        // shared mesh code's.
        if value < 0.0 {
            return Err(format!(
                "face {face} has the vertex index {value}: out of range (negative)"
            ));
        }
        self.polygon.push(value.min(u32::MAX as f64) as u32);
        Ok(())
    }
}

fn truncated(element: &Element, read: usize) -> String {
    format!(
        "truncated file: expected {} {}, read {read}",
        element.count,
        element.noun()
    )
}

/// Parses a PLY file's bytes into positions and triangles (0-based indices).
pub fn parse(data: &[u8]) -> Result<RawMesh, String> {
    let header = parse_header(data)?;
    let layout = layout(&header.elements)?;
    let body = &data[header.body..];
    let vertices = header.elements[layout.vertex].count;
    let faces = header.elements[layout.face].count;
    // Counts come from the file: a corrupt one must not allocate before the data says it
    // exists (a record is at least one byte, or two characters in ascii).
    let mut b = Builder {
        positions: Vec::with_capacity(vertices.min(body.len())),
        normals: Vec::new(),
        uvs: Vec::new(),
        triangles: Vec::with_capacity(faces.min(body.len())),
        polygon: Vec::new(),
    };
    match header.format {
        Format::Ascii => parse_ascii(body, &header.elements, &layout, &mut b)?,
        Format::Binary { big } => parse_binary(body, big, &header.elements, &layout, &mut b)?,
    }
    // Normals and texture coordinates belong to the vertices: indexed as the positions are.
    let normal_triangles = if b.normals.is_empty() {
        Vec::new()
    } else {
        b.triangles.clone()
    };
    let uv_triangles = if b.uvs.is_empty() {
        Vec::new()
    } else {
        b.triangles.clone()
    };
    Ok(RawMesh {
        positions: b.positions,
        triangles: b.triangles,
        first_index: 0,
        normals: b.normals,
        normal_triangles,
        uvs: b.uvs,
        uv_triangles,
        face_normals: false,
        attribute: None,
    })
}

fn parse_ascii(
    body: &[u8],
    elements: &[Element],
    layout: &Layout,
    b: &mut Builder,
) -> Result<(), String> {
    let text = std::str::from_utf8(body).map_err(|e| {
        format!(
            "the ascii data is not text (byte {} after the header)",
            e.valid_up_to()
        )
    })?;
    let mut tokens = text.split_ascii_whitespace();
    for (e, element) in elements.iter().enumerate() {
        for record in 0..element.count {
            let mut fields = [0.0f32; FIELDS];
            for (p, property) in element.properties.iter().enumerate() {
                let mut value = |ty: Scalar| -> Result<f64, String> {
                    let token = tokens.next().ok_or_else(|| truncated(element, record))?;
                    ty.parse_value(token).ok_or_else(|| {
                        format!(
                            "{} {record}: {token:?} is not a valid {ty:?} for property `{}`",
                            element.name, property.name
                        )
                    })
                };
                match property.kind {
                    Kind::Scalar(ty) => {
                        let v = value(ty)?;
                        if e == layout.vertex
                            && let Some(f) = layout.slots[p]
                        {
                            fields[f] = v as f32;
                        }
                    }
                    Kind::List { count, item } => {
                        let n = value(count)?;
                        if n < 0.0 {
                            return Err(format!(
                                "{} {record}: negative list length {n} for property `{}`",
                                element.name, property.name
                            ));
                        }
                        let wanted = e == layout.face && p == layout.indices;
                        for _ in 0..n as usize {
                            let v = value(item)?;
                            if wanted {
                                b.index(record, v)?;
                            }
                        }
                        if wanted {
                            b.end_face(record)?;
                        }
                    }
                }
            }
            if e == layout.vertex {
                b.vertex(layout, &fields);
            }
        }
    }
    Ok(())
}

/// The binary face element at the start of `body` decoded on every thread, if every face is a
/// triangle (the common case; its records then have one size) with non-negative indices, and
/// the bytes it took. None sends the element to the record-by-record reader, which also words
/// the errors.
fn triangles_only(
    body: &[u8],
    big: bool,
    element: &Element,
    layout: &Layout,
) -> Option<(Vec<[u32; 3]>, usize)> {
    // Bytes before the index list, the list's count and item types, bytes after it.
    let (mut before, mut after, mut list) = (0, 0, None);
    for (p, property) in element.properties.iter().enumerate() {
        match property.kind {
            Kind::Scalar(ty) if list.is_none() => before += ty.size(),
            Kind::Scalar(ty) => after += ty.size(),
            Kind::List { count, item } if p == layout.indices => list = Some((count, item)),
            Kind::List { .. } => return None,
        }
    }
    let (count, item) = list?;
    let size = before + count.size() + 3 * item.size() + after;
    let bytes = body.get(..element.count.checked_mul(size)?)?;
    let triangle = |r: &[u8]| -> Option<[u32; 3]> {
        if count.read(&r[before..], big) != 3.0 {
            return None;
        }
        let mut t = [0u32; 3];
        for (k, slot) in t.iter_mut().enumerate() {
            let v = item.read(&r[before + count.size() + k * item.size()..], big);
            if v < 0.0 {
                return None;
            }
            // As Builder::index.
            *slot = v.min(u32::MAX as f64) as u32;
        }
        Some(t)
    };
    let triangles = bytes
        .par_chunks_exact(size)
        .map(triangle)
        .collect::<Option<Vec<_>>>()?;
    Some((triangles, bytes.len()))
}

fn parse_binary(
    body: &[u8],
    big: bool,
    elements: &[Element],
    layout: &Layout,
    b: &mut Builder,
) -> Result<(), String> {
    let mut pos = 0;
    for (e, element) in elements.iter().enumerate() {
        if let Some(size) = element.fixed_size() {
            if size == 0 {
                // Records without properties take no bytes.
                continue;
            }
            // Fixed-size records: the common vertex layout, read straight from the bytes.
            let available = (body.len() - pos) / size;
            if available < element.count {
                return Err(truncated(element, available));
            }
            let bytes = &body[pos..pos + size * element.count];
            pos += bytes.len();
            if e == layout.vertex {
                // (field, byte offset, type) of each property read.
                let mut wanted = Vec::new();
                let mut offset = 0;
                for (p, q) in element.properties.iter().enumerate() {
                    let Kind::Scalar(ty) = q.kind else {
                        unreachable!("fixed-size records have no lists")
                    };
                    if let Some(f) = layout.slots[p] {
                        wanted.push((f, offset, ty));
                    }
                    offset += ty.size();
                }
                let read = |r: &[u8]| {
                    let mut fields = [0.0f32; FIELDS];
                    for &(f, o, ty) in &wanted {
                        fields[f] = ty.read(&r[o..], big) as f32;
                    }
                    fields
                };
                if element.count > PARALLEL {
                    let all: Vec<[f32; FIELDS]> = bytes.par_chunks_exact(size).map(read).collect();
                    b.vertices(layout, &all);
                } else {
                    b.positions.reserve(element.count);
                    for r in bytes.chunks_exact(size) {
                        b.vertex(layout, &read(r));
                    }
                }
            }
            continue;
        }
        if e == layout.face
            && element.count > PARALLEL
            && let Some(read) = triangles_only(&body[pos..], big, element, layout)
        {
            b.triangles.extend(read.0);
            pos += read.1;
            continue;
        }
        // Records with lists: walk them property by property.
        for record in 0..element.count {
            let mut fields = [0.0f32; FIELDS];
            for (p, property) in element.properties.iter().enumerate() {
                let mut take = |ty: Scalar| -> Result<f64, String> {
                    let bytes = body
                        .get(pos..pos + ty.size())
                        .ok_or_else(|| truncated(element, record))?;
                    pos += ty.size();
                    Ok(ty.read(bytes, big))
                };
                match property.kind {
                    Kind::Scalar(ty) => {
                        let v = take(ty)?;
                        if e == layout.vertex
                            && let Some(f) = layout.slots[p]
                        {
                            fields[f] = v as f32;
                        }
                    }
                    Kind::List { count, item } => {
                        let n = take(count)?;
                        if n < 0.0 {
                            return Err(format!(
                                "{} {record}: negative list length {n} for property `{}`",
                                element.name, property.name
                            ));
                        }
                        let n = n as usize;
                        if e == layout.face && p == layout.indices {
                            for _ in 0..n {
                                let v = take(item)?;
                                b.index(record, v)?;
                            }
                            b.end_face(record)?;
                        } else {
                            let skip = n * item.size();
                            if body.len() - pos < skip {
                                return Err(truncated(element, record));
                            }
                            pos += skip;
                        }
                    }
                }
            }
            if e == layout.vertex {
                b.vertex(layout, &fields);
            }
        }
    }
    Ok(())
}

/// A mesh attribute of a PLY file: its values per vertex, or per triangle of the fan-triangulated
/// faces (a face's value on each of its triangles).
#[derive(Clone, Debug, PartialEq)]
pub struct Attribute {
    pub per_face: bool,
    /// One or three channels; a single channel is copied to all three.
    pub values: Vec<Vec3>,
}

/// The names Mitsuba 3 gives the extra properties of element `prefix` (`vertex_` or `face_`),
/// with the indices of the properties each reads: `r g b` (or `red green blue`) is
/// `{prefix}color`; consecutive `{name}_{c}` with c running over `x y z`, `r g b`, `0 1 2` or
/// `1 2 3` (one or three of them) is `{prefix}{name}`, `_color` added for `r g b`. Other
/// properties (lists, `reserved` ones, any that break the scheme) belong to none.
fn attribute_groups(
    prefix: &str,
    props: &[Property],
    reserved: &[&str],
) -> Vec<(String, Vec<usize>)> {
    let scalar = |i: usize| matches!(props[i].kind, Kind::Scalar(_));
    let find = |n: &str| {
        props
            .iter()
            .position(|p| p.name == n)
            .filter(|&i| scalar(i))
    };
    let mut groups = Vec::new();
    let mut prefixes: Vec<&str> = Vec::new();
    let mut taken = vec![false; props.len()];
    for names in [["r", "g", "b"], ["red", "green", "blue"]] {
        if let [Some(r), Some(g), Some(b)] = names.map(find) {
            groups.push((format!("{prefix}color"), vec![r, g, b]));
            for i in [r, g, b] {
                taken[i] = true;
            }
            break;
        }
    }
    const SCHEMES: [[char; 3]; 4] = [
        ['x', 'y', 'z'],
        ['r', 'g', 'b'],
        ['0', '1', '2'],
        ['1', '2', '3'],
    ];
    let split = |i: usize| -> Option<(&str, char)> {
        let (name, c) = props[i].name.rsplit_once('_')?;
        let mut cs = c.chars();
        let c = cs.next()?;
        cs.next().is_none().then_some((name, c))
    };
    let mut i = 0;
    while i < props.len() {
        if taken[i] || !scalar(i) || reserved.contains(&props[i].name.as_str()) {
            i += 1;
            continue;
        }
        let Some((name, c)) = split(i) else {
            i += 1;
            continue;
        };
        let Some(scheme) = SCHEMES.iter().position(|s| s[0] == c) else {
            i += 1;
            continue;
        };
        let mut members = vec![i];
        while members.len() < 3 {
            let j = i + members.len();
            let next = (j < props.len() && scalar(j) && !taken[j])
                .then(|| split(j))
                .flatten();
            match next {
                Some((n, c)) if n == name && c == SCHEMES[scheme][members.len()] => members.push(j),
                _ => break,
            }
        }
        i += members.len();
        // Mitsuba 3 keeps one or three channels, and the first group of a name.
        if members.len() == 2 || prefixes.contains(&name) {
            continue;
        }
        prefixes.push(name);
        let color = if scheme == 1 { "_color" } else { "" };
        groups.push((format!("{prefix}{name}{color}"), members));
    }
    groups
}

/// Reads the values of the PLY's scalar properties one record at a time, in ascii or binary.
enum Cursor<'a> {
    Ascii(std::str::SplitAsciiWhitespace<'a>),
    Binary {
        body: &'a [u8],
        pos: usize,
        big: bool,
    },
}

impl Cursor<'_> {
    fn next(&mut self, ty: Scalar, element: &Element, record: usize) -> Result<f64, String> {
        match self {
            Cursor::Ascii(tokens) => {
                let token = tokens.next().ok_or_else(|| truncated(element, record))?;
                ty.parse_value(token).ok_or_else(|| {
                    format!("{} {record}: {token:?} is not a valid {ty:?}", element.name)
                })
            }
            Cursor::Binary { body, pos, big } => {
                let bytes = body
                    .get(*pos..*pos + ty.size())
                    .ok_or_else(|| truncated(element, record))?;
                *pos += ty.size();
                Ok(ty.read(bytes, *big))
            }
        }
    }
}

/// The mesh attribute `name` of a PLY file (named as Mitsuba 3 names them: `vertex_color`,
/// `face_weight`, ...; see [`attribute_groups`]), or None if the file has none of that name.
/// Names it has are listed in the error of a caller that needs one.
pub fn attribute(data: &[u8], name: &str) -> Result<Option<Attribute>, String> {
    let header = parse_header(data)?;
    let layout = layout(&header.elements)?;
    let (vertex_groups, face_groups) = all_groups(&header, &layout);
    let (per_face, members) = match (
        vertex_groups.iter().find(|(n, _)| n == name),
        face_groups.iter().find(|(n, _)| n == name),
    ) {
        (Some((_, m)), _) => (false, m.clone()),
        (None, Some((_, m))) => (true, m.clone()),
        (None, None) => return Ok(None),
    };
    let wanted = if per_face { layout.face } else { layout.vertex };
    let body = &data[header.body..];
    let mut cursor = match header.format {
        Format::Ascii => Cursor::Ascii(
            std::str::from_utf8(body)
                .map_err(|e| {
                    format!(
                        "the ascii data is not text (byte {} after the header)",
                        e.valid_up_to()
                    )
                })?
                .split_ascii_whitespace(),
        ),
        Format::Binary { big } => Cursor::Binary { body, pos: 0, big },
    };
    let mut values = Vec::new();
    for (e, element) in header.elements.iter().enumerate() {
        for record in 0..element.count {
            let mut v = [0.0f32; 3];
            let mut corners = 0usize;
            for (p, property) in element.properties.iter().enumerate() {
                match property.kind {
                    Kind::Scalar(ty) => {
                        let x = cursor.next(ty, element, record)?;
                        if e == wanted
                            && let Some(k) = members.iter().position(|&m| m == p)
                        {
                            v[k] = x as f32;
                        }
                    }
                    Kind::List { count, item } => {
                        let n = cursor.next(count, element, record)?;
                        if !(0.0..=1e9).contains(&n) {
                            return Err(format!(
                                "{} {record}: bad list length {n} for property `{}`",
                                element.name, property.name
                            ));
                        }
                        if e == layout.face && p == layout.indices {
                            corners = n as usize;
                        }
                        for _ in 0..n as usize {
                            cursor.next(item, element, record)?;
                        }
                    }
                }
            }
            if e != wanted {
                continue;
            }
            let value = if members.len() == 1 {
                Vec3::splat(v[0])
            } else {
                Vec3::from(v)
            };
            if per_face {
                // One value per triangle of the face's fan, as `Builder::end_face` makes them.
                for _ in 2..corners.max(2) {
                    values.push(value);
                }
            } else {
                values.push(value);
            }
        }
        if e == wanted {
            break;
        }
    }
    Ok(Some(Attribute { per_face, values }))
}

/// The names of the mesh attributes a PLY file has (for messages).
pub fn attribute_names(data: &[u8]) -> Vec<String> {
    let Ok(header) = parse_header(data) else {
        return Vec::new();
    };
    let Ok(layout) = layout(&header.elements) else {
        return Vec::new();
    };
    let (vertex, face) = all_groups(&header, &layout);
    vertex.into_iter().chain(face).map(|(n, _)| n).collect()
}

/// The attribute groups of the vertex and of the face element ([`attribute_groups`]).
type Groups = Vec<(String, Vec<usize>)>;
fn all_groups(header: &Header, layout: &Layout) -> (Groups, Groups) {
    // What the mesh itself reads of a vertex (`field_of`'s names).
    let reserved: Vec<&str> = header.elements[layout.vertex]
        .properties
        .iter()
        .map(|p| p.name.as_str())
        .filter(|n| field_of(n).is_some())
        .collect();
    (
        attribute_groups(
            "vertex_",
            &header.elements[layout.vertex].properties,
            &reserved,
        ),
        attribute_groups("face_", &header.elements[layout.face].properties, &[]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3's grouping of extra properties into attributes, and their values: `red green
    /// blue` is a colour, `NAME_x NAME_y NAME_z` and `NAME_r NAME_g NAME_b` three channels (the
    /// latter `_color`), `NAME_1` one, two channels and unsuffixed names none; a quad face's
    /// value goes to both of its triangles.
    #[test]
    fn extra_properties_group_into_mitsubas_attributes() {
        let file = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
            property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n\
            property float dir_x\nproperty float dir_y\nproperty float dir_z\nproperty float tint_r\n\
            property float tint_g\nproperty float tint_b\nproperty float pair_0\nproperty float pair_1\n\
            property float quality\nelement face 1\nproperty list uchar int vertex_indices\n\
            property float age_1\nend_header\n\
            0 0 0 255 0 10 1 2 3 .1 .2 .3 7 8 9\n1 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n\
            1 1 0 0 0 0 0 0 0 0 0 0 0 0 0\n0 1 0 0 0 0 0 0 0 0 0 0 0 0 0\n4 0 1 2 3 0.25\n";
        let data = file.as_bytes();
        assert_eq!(
            attribute_names(data),
            [
                "vertex_color",
                "vertex_dir",
                "vertex_tint_color",
                "face_age"
            ]
        );
        let colour = attribute(data, "vertex_color").unwrap().unwrap();
        assert!(!colour.per_face);
        // Integer colours are taken as they are, as Mitsuba 3 takes them.
        assert_eq!(colour.values[0], Vec3::new(255.0, 0.0, 10.0));
        assert_eq!(
            attribute(data, "vertex_dir").unwrap().unwrap().values[0],
            Vec3::new(1.0, 2.0, 3.0)
        );
        let age = attribute(data, "face_age").unwrap().unwrap();
        assert!(age.per_face);
        assert_eq!(age.values, vec![Vec3::splat(0.25); 2]);
        assert_eq!(attribute(data, "vertex_pair").unwrap(), None);
        assert_eq!(attribute(data, "vertex_quality").unwrap(), None);
    }

    /// A binary PLY of a `n` x `n` vertex grid (z = x y / n, with normals) and its triangles,
    /// each face `3 a b c` after a `uchar` flag, with `quad` written as one quad in place of
    /// the first two triangles, in either byte order.
    fn grid(n: u32, big: bool, quad: bool, flip: Option<(usize, i32)>) -> (Vec<u8>, Vec<[u32; 3]>) {
        let mut tris = Vec::new();
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                let a = i * n + j;
                tris.push([a, a + n, a + n + 1]);
                tris.push([a, a + n + 1, a + 1]);
            }
        }
        let faces = if quad { tris.len() - 1 } else { tris.len() };
        let mut out = format!(
            "ply\nformat binary_{}_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face {faces}\nproperty uchar flags\nproperty list uchar int vertex_indices\nend_header\n",
            if big { "big" } else { "little" },
            n * n
        )
        .into_bytes();
        let f32s = |out: &mut Vec<u8>, x: f32| {
            out.extend(if big {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            })
        };
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (i as f32, j as f32);
                for v in [x, y, x * y / n as f32, 0.0, 0.0, 1.0] {
                    f32s(&mut out, v);
                }
            }
        }
        let i32s = |out: &mut Vec<u8>, x: i32| {
            out.extend(if big {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            })
        };
        for (f, t) in tris.iter().enumerate() {
            if quad && f == 1 {
                continue;
            }
            out.push(7);
            if quad && f == 0 {
                // The quad a, a+n, a+n+1, a+1 fans into the first two triangles.
                out.push(4);
                for v in [t[0], t[1], t[2], tris[1][2]] {
                    i32s(&mut out, v as i32);
                }
                continue;
            }
            out.push(3);
            for (k, &v) in t.iter().enumerate() {
                let v = match flip {
                    Some((face, value)) if face == f && k == 1 => value,
                    _ => v as i32,
                };
                i32s(&mut out, v);
            }
        }
        (out, tris)
    }

    /// Mutated PLY files (ascii, both binary byte orders; a few large enough for the parallel
    /// readers), then what decodes through the shared mesh code: errors, never a panic.
    /// `FOTON_FUZZ_PLY=N` runs N small ones instead of 20,000 (a million took 10 s on one 2-vCPU
    /// machine).
    #[test]
    fn mutated_files_are_errors_or_meshes_never_panics() {
        let n: usize = std::env::var("FOTON_FUZZ_PLY")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(20_000);
        let ascii = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n3 0 1 2\n4 0 2 3 1\n".to_vec();
        // With extra properties, which `attribute` reads.
        let attributes = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nproperty float weight_0\nend_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2 0.5\n".to_vec();
        let small = [
            ascii,
            attributes,
            grid(6, false, true, None).0,
            grid(6, true, false, None).0,
        ];
        let large = grid(200, false, false, None).0;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |m: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % m.max(1) as u64) as usize
        };
        let mut outcomes = [0usize; 2];
        for i in 0..n + 50 {
            let mut f = if i < n {
                small[next(small.len())].clone()
            } else {
                large.clone()
            };
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
            let result = parse(&f);
            outcomes[result.is_ok() as usize] += 1;
            for name in ["vertex_color", "face_weight"] {
                if let Ok(Some(a)) = attribute(&f, name)
                    && let Ok(raw) = &result
                {
                    let n = if a.per_face {
                        raw.triangles.len()
                    } else {
                        raw.positions.len()
                    };
                    // Where both passes read the file, they agree on the element's size.
                    assert_eq!(a.values.len(), n, "{name}");
                }
            }
            let _ = attribute_names(&f);
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
        assert!(outcomes[0] > 0 && outcomes[1] > 0, "{outcomes:?}");
    }

    #[test]
    fn large_binary_meshes_decode_alike_on_every_thread() {
        // 200 x 200 vertices, 79,202 triangles: above PARALLEL for both elements.
        for big in [false, true] {
            for quad in [false, true] {
                let (bytes, tris) = grid(200, big, quad, None);
                let raw = parse(&bytes).unwrap();
                // Not assert_eq: a failure would print 80,000 triangles.
                assert!(raw.triangles == tris, "big {big} quad {quad}");
                assert_eq!(raw.positions.len(), 200 * 200);
                assert_eq!(raw.positions[201], Vec3::new(1.0, 1.0, 1.0 / 200.0));
                assert_eq!(raw.normals.len(), 200 * 200);
                assert_eq!(raw.normals[7], Vec3::Z);
            }
        }
        // A negative index far into the faces is reported with its face, as by the
        // record-by-record reader.
        let (bytes, _) = grid(200, false, false, Some((50_000, -2)));
        let e = parse(&bytes).unwrap_err();
        assert!(e.contains("face 50000 has the vertex index -2"), "{e}");
        // Cut in the faces: truncated, whichever reader saw it.
        let (bytes, _) = grid(200, true, false, None);
        let e = parse(&bytes[..bytes.len() - 100]).unwrap_err();
        assert!(e.contains("truncated"), "{e}");
    }
}
