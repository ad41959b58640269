//! Stanford PLY meshes (ascii, binary little- and big-endian): vertex positions and faces.
//!
//! Only `x y z` of the vertices and the `vertex_indices` (or `vertex_index`) list of the faces
//! are read; every other property and element is read past. Polygons are fan-triangulated,
//! the same way tobj triangulates OBJ faces, so that an OBJ and a PLY of one model give the
//! same triangles. Errors are plain text; the caller adds the file and the scene key.

use super::mesh::RawMesh;
use glam::Vec3;

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
    xyz: [usize; 3],
    face: usize,
    indices: usize,
}

fn layout(elements: &[Element]) -> Result<Layout, String> {
    let find = |name: &str| elements.iter().position(|e| e.name == name);
    let vertex = find("vertex").ok_or("the PLY file has no `vertex` element")?;
    let mut xyz = [0; 3];
    for (slot, axis) in xyz.iter_mut().zip(["x", "y", "z"]) {
        let props = &elements[vertex].properties;
        *slot = props.iter().position(|p| p.name == axis).ok_or_else(|| {
            format!("the `vertex` element has no `{axis}` property (vertices need x, y and z)")
        })?;
        if matches!(props[*slot].kind, Kind::List { .. }) {
            return Err(format!(
                "the vertex property `{axis}` is a list; expected a number"
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
        xyz,
        face,
        indices,
    })
}

/// Accumulates the positions and fan-triangulated faces as the elements are read.
struct Builder {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    polygon: Vec<u32>,
}

impl Builder {
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
        triangles: Vec::with_capacity(faces.min(body.len())),
        polygon: Vec::new(),
    };
    match header.format {
        Format::Ascii => parse_ascii(body, &header.elements, &layout, &mut b)?,
        Format::Binary { big } => parse_binary(body, big, &header.elements, &layout, &mut b)?,
    }
    Ok(RawMesh {
        positions: b.positions,
        triangles: b.triangles,
        first_index: 0,
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
            let mut xyz = Vec3::ZERO;
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
                            && let Some(axis) = layout.xyz.iter().position(|&i| i == p)
                        {
                            xyz[axis] = v as f32;
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
                b.positions.push(xyz);
            }
        }
    }
    Ok(())
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
                let mut offsets = [(0, Scalar::F32); 3];
                for (slot, &p) in offsets.iter_mut().zip(&layout.xyz) {
                    let offset: usize = element.properties[..p]
                        .iter()
                        .map(|q| match q.kind {
                            Kind::Scalar(t) => t.size(),
                            Kind::List { .. } => unreachable!("fixed-size records"),
                        })
                        .sum();
                    let Kind::Scalar(ty) = element.properties[p].kind else {
                        unreachable!("layout() checked that x, y, z are scalars")
                    };
                    *slot = (offset, ty);
                }
                b.positions.extend(bytes.chunks_exact(size).map(|r| {
                    let get = |(o, t): (usize, Scalar)| t.read(&r[o..], big) as f32;
                    Vec3::new(get(offsets[0]), get(offsets[1]), get(offsets[2]))
                }));
            }
            continue;
        }
        // Records with lists: walk them property by property.
        for record in 0..element.count {
            let mut xyz = Vec3::ZERO;
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
                            && let Some(axis) = layout.xyz.iter().position(|&i| i == p)
                        {
                            xyz[axis] = v as f32;
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
                b.positions.push(xyz);
            }
        }
    }
    Ok(())
}
