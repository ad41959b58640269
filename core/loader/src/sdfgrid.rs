//! Mitsuba 3's `sdfgrid` shape as a triangle mesh.
//!
//! Mitsuba 3 defines the shape by a signed distance field sampled on a lattice (a
//! single-channel `.vol` grid): its object space is the unit cube, the samples sit at the
//! corners of the (Nx-1)(Ny-1)(Nz-1) cells (sample (i, j, k) at (i/(Nx-1), j/(Ny-1),
//! k/(Nz-1))), the field inside a cell is the trilinear interpolant of the cell's 8 corner
//! values, and the surface is the zero level set of that piecewise-trilinear field, with the
//! field increasing outwards. Its geometric normal is the normalised gradient of the
//! interpolant of the cell the point lies in; its shading normal is either that (`analytic`)
//! or, by default (`smooth`), the blend of the normalised gradients of the eight cells around
//! the nearest lattice vertex (Hansson-Söderlund, Evans and Akenine-Möller, "Ray Tracing of
//! Signed Distance Function Grids", JCGT 11(3), 2022).
//!
//! foton renders that zero set as a fine triangle mesh rather than by intersecting the cubic
//! in each cell. Each cell the surface passes through is subdivided into `subdivisions`^3
//! sub-cubes, the exact trilinear interpolant is sampled at their corners, and each sub-cube
//! is polygonised by marching tetrahedra on its Kuhn (Freudenthal) triangulation into six
//! tetrahedra around the main diagonal. Vertices lie on the exact zero of the interpolant
//! along their tetrahedron edge, so the mesh's vertices are on Mitsuba's surface and only
//! the flat triangles between them depart from it, by O((cell / subdivisions)^2).

use foton_core::medium::grid::VolFile;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// How the shading normals of an `sdfgrid` are computed (Mitsuba's `normals` parameter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SdfNormals {
    /// The trilinear blend of the normalised gradients of the eight cells around the nearest
    /// lattice vertex (Hansson-Söderlund et al. 2022): continuous across cells. Mitsuba's
    /// default.
    Smooth,
    /// The normalised gradient of the interpolant of the cell the point lies in: the
    /// geometric normal, discontinuous across cells.
    Analytic,
}

/// The zero level set of an `sdfgrid` as triangles, in the grid's object space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SdfMesh {
    /// Triangles in object space ([0,1]^3), wound so that (b-a)x(c-a) points towards increasing field (outward).
    pub triangles: Vec<[Vec3; 3]>,
    /// Per triangle, the shading normal at each corner (object space, unit length; transform as normals later).
    pub normals: Vec<[Vec3; 3]>,
}

/// The most sub-cubes per cell and axis: the per-thread edge table grows with its cube, and
/// far beyond this the triangles are smaller than anything the field resolves.
pub const MAX_SUBDIVISIONS: usize = 64;

/// The triangles of the zero level set of `vol`'s signed distance field, each cell the surface
/// crosses cut into `subdivisions`^3 sub-cubes, with shading normals by `normals`.
///
/// The result is watertight where the surface is closed, and the same, in the same order,
/// on every run and thread count.
pub fn sdf_mesh(
    vol: &VolFile,
    normals: SdfNormals,
    subdivisions: usize,
) -> Result<SdfMesh, String> {
    if vol.channels != 1 {
        return Err(format!(
            "sdfgrid needs one channel, the file has {}",
            vol.channels
        ));
    }
    if let Some(axis) = (0..3).find(|&a| vol.res[a] < 2) {
        return Err(format!(
            "sdfgrid needs at least 2 samples along each axis, the file has {} along {}",
            vol.res[axis],
            ["x", "y", "z"][axis]
        ));
    }
    let count = vol.res.iter().try_fold(1usize, |n, &r| n.checked_mul(r));
    if count != Some(vol.values.len()) {
        return Err(format!(
            "a {} x {} x {} sdfgrid needs as many values, the file has {}",
            vol.res[0],
            vol.res[1],
            vol.res[2],
            vol.values.len()
        ));
    }
    if let Some(at) = vol.values.iter().position(|v| !v.is_finite()) {
        let (x, yz) = (at % vol.res[0], at / vol.res[0]);
        let (y, z) = (yz % vol.res[1], yz / vol.res[1]);
        return Err(format!(
            "sdfgrid value ({x}, {y}, {z}) is {}: every value must be finite",
            vol.values[at]
        ));
    }
    if subdivisions == 0 || subdivisions > MAX_SUBDIVISIONS {
        return Err(format!(
            "sdfgrid subdivisions {subdivisions}: must be 1 to {MAX_SUBDIVISIONS}"
        ));
    }
    let field = Field::new(vol);
    let occupied: Vec<[usize; 3]> = field.cells().filter(|&c| field.occupied(c)).collect();
    if occupied.is_empty() {
        return Err("the grid has no surface: every value has the same sign".into());
    }
    let cases = Cases::new();
    let per_cell: Vec<Vec<Triangle>> = occupied
        .par_iter()
        .map_init(
            || Scratch::new(subdivisions),
            |scratch, &cell| {
                let mut out = Vec::new();
                mesh_cell(&field, &cases, normals, cell, scratch, &mut out);
                out
            },
        )
        .collect();
    let total = per_cell.iter().map(Vec::len).sum();
    let mut mesh = SdfMesh {
        triangles: Vec::with_capacity(total),
        normals: Vec::with_capacity(total),
    };
    for (positions, shading) in per_cell.into_iter().flatten() {
        mesh.triangles.push(positions);
        mesh.normals.push(shading);
    }
    if mesh.triangles.is_empty() {
        // Occupied cells whose only zeros are samples that are exactly 0, next to values of
        // one sign: a surface of no area, which `mesh_cell`, counting 0 as positive, leaves
        // out.
        return Err(
            "the grid has no surface: no value is below zero next to one at or above it".into(),
        );
    }
    Ok(mesh)
}

/// A triangle's corners and their shading normals.
type Triangle = ([Vec3; 3], [Vec3; 3]);

/// The grid's samples, addressed by lattice index (sample (i, j, k) at lattice point (i, j, k),
/// object point (i, j, k) / (N - 1)).
struct Field<'a> {
    res: [usize; 3],
    values: &'a [f32],
    /// N - 1 per axis: lattice units per object unit, the factor between a gradient in
    /// lattice coordinates and one in object space.
    scale: DVec3,
}

impl<'a> Field<'a> {
    fn new(vol: &'a VolFile) -> Self {
        let scale = DVec3::new(
            (vol.res[0] - 1) as f64,
            (vol.res[1] - 1) as f64,
            (vol.res[2] - 1) as f64,
        );
        Field {
            res: vol.res,
            values: &vol.values,
            scale,
        }
    }

    fn at(&self, i: [usize; 3]) -> f64 {
        self.values[(i[2] * self.res[1] + i[1]) * self.res[0] + i[0]] as f64
    }

    fn cells(&self) -> impl Iterator<Item = [usize; 3]> + '_ {
        let [nx, ny, nz] = self.res;
        (0..nz - 1)
            .flat_map(move |k| (0..ny - 1).flat_map(move |j| (0..nx - 1).map(move |i| [i, j, k])))
    }

    /// The cell's corner values, indexed x + 2y + 4z relative to its lower corner.
    fn corners(&self, cell: [usize; 3]) -> [f64; 8] {
        std::array::from_fn(|b| {
            self.at([
                cell[0] + (b & 1),
                cell[1] + ((b >> 1) & 1),
                cell[2] + (b >> 2),
            ])
        })
    }

    /// Whether the cell can hold surface: a trilinear interpolant is a convex combination of
    /// its corners, so corners all of one strict sign keep it off zero (Mitsuba's test).
    fn occupied(&self, cell: [usize; 3]) -> bool {
        let c = self.corners(cell);
        let (low, high) = c
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        !(low > 0.0 || high < 0.0)
    }

    /// The cell containing lattice point `q` (the last one on the upper faces).
    fn cell_of(&self, q: DVec3) -> [usize; 3] {
        let q = q.to_array();
        std::array::from_fn(|a| (q[a].floor().max(0.0) as usize).min(self.res[a] - 2))
    }

    /// The object-space gradient of the interpolant of a cell (its `corners`) at its local
    /// coordinates `l`:
    /// Mitsuba's geometric normal, before normalisation.
    fn gradient(&self, corners: &[f64; 8], l: DVec3) -> DVec3 {
        trilerp_gradient(corners, l) * self.scale
    }

    /// Mitsuba 3's smooth shading normal at lattice point `q` (Hansson-Söderlund et al. 2022,
    /// as Mitsuba implements it), before normalisation; zero where it is undefined.
    ///
    /// The eight cells are those around the lattice vertex nearest to `q`; `v` is the lower
    /// corner of the lowest. A cell's gradient along an axis is the difference of the field
    /// across the cell's extent along that axis, taken at `q`'s position along the other two
    /// (in the cell containing `q`): within the cell this is the gradient of its interpolant,
    /// and it depends only on the cell's index along that axis. Cells below the grid are
    /// dropped and the blend along that axis goes wholly to the upper one; a cell above it
    /// keeps its weight, its difference along that axis zero because the sample index is
    /// clamped. Both follow Mitsuba's code (src/shapes/sdfgrid.cpp, `smooth`) rather than the
    /// plainer reading of the paper, each cell's own interpolant extrapolated to `q`: the two
    /// differ only off the cell containing `q`, at second order, and at the upper faces.
    fn smooth(&self, q: DVec3) -> DVec3 {
        let cell = self.cell_of(q);
        let q = q.to_array();
        let w: [f64; 3] = std::array::from_fn(|a| q[a] - cell[a] as f64);
        let v: [i64; 3] = std::array::from_fn(|a| q[a].round() as i64 - 1);
        let stride = [1, self.res[0], self.res[0] * self.res[1]];
        let scale = self.scale.to_array();
        // d[o][a]: the difference along a of the cell with index v + o along a.
        let mut d = [[0.0; 3]; 2];
        for a in 0..3 {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            let (sb, sc) = (stride[b], stride[c]);
            let across = cell[b] * sb + cell[c] * sc;
            let last = self.res[a] as i64 - 1;
            // The interpolant on sample plane k across a, at q along the other two axes.
            let plane = |k: i64| {
                let i = across + k.clamp(0, last) as usize * stride[a];
                let f = |i: usize| self.values[i] as f64;
                lerp(
                    lerp(f(i), f(i + sb), w[b]),
                    lerp(f(i + sc), f(i + sb + sc), w[b]),
                    w[c],
                )
            };
            let (p0, p1, p2) = (plane(v[a]), plane(v[a] + 1), plane(v[a] + 2));
            d[0][a] = (p1 - p0) * scale[a];
            d[1][a] = (p2 - p1) * scale[a];
        }
        let squares = d.map(|o| o.map(|x| x * x));
        let uvw: [f64; 3] = std::array::from_fn(|a| {
            if v[a] < 0 {
                1.0
            } else {
                q[a] - v[a] as f64 - 0.5
            }
        });
        let mut blend = DVec3::ZERO;
        for i in 0..8 {
            let [x, y, z] = [i & 1, (i >> 1) & 1, i >> 2];
            if (x == 0 && v[0] < 0) || (y == 0 && v[1] < 0) || (z == 0 && v[2] < 0) {
                continue;
            }
            let length2 = squares[x][0] + squares[y][1] + squares[z][2];
            if length2 > 0.0 {
                let weight = |o: usize, a: usize| if o == 1 { uvw[a] } else { 1.0 - uvw[a] };
                let weight = weight(x, 0) * weight(y, 1) * weight(z, 2) / length2.sqrt();
                blend += weight * DVec3::new(d[x][0], d[y][1], d[z][2]);
            }
        }
        blend
    }
}

/// Exact at t = 0 and t = 1 (unlike a + t (b - a)), so that two cells evaluating their
/// interpolants on the face they share get bitwise the same value, and neighbouring cells
/// classify and place the vertices on it identically: the mesh has no cracks.
fn lerp(a: f64, b: f64, t: f64) -> f64 {
    (1.0 - t) * a + t * b
}

/// The trilinear interpolant of corner values `c` (indexed x + 2y + 4z) at local `l`.
fn trilerp(c: &[f64; 8], l: DVec3) -> f64 {
    lerp(
        lerp(lerp(c[0], c[1], l.x), lerp(c[2], c[3], l.x), l.y),
        lerp(lerp(c[4], c[5], l.x), lerp(c[6], c[7], l.x), l.y),
        l.z,
    )
}

/// The gradient of [`trilerp`] in local coordinates.
fn trilerp_gradient(c: &[f64; 8], l: DVec3) -> DVec3 {
    DVec3::new(
        lerp(
            lerp(c[1] - c[0], c[3] - c[2], l.y),
            lerp(c[5] - c[4], c[7] - c[6], l.y),
            l.z,
        ),
        lerp(
            lerp(c[2] - c[0], c[3] - c[1], l.x),
            lerp(c[6] - c[4], c[7] - c[5], l.x),
            l.z,
        ),
        lerp(
            lerp(c[4] - c[0], c[5] - c[1], l.x),
            lerp(c[6] - c[2], c[7] - c[3], l.x),
            l.y,
        ),
    )
}

/// A tetrahedron edge the surface crosses, as sub-cube corners (x + 2y + 4z): the negative
/// end, then the non-negative one.
type Edge = [u8; 2];

/// Marching tetrahedra on the Kuhn triangulation of a cube: per tetrahedron and per pattern
/// of negative vertices, the triangles of the zero set, wound outward.
struct Cases {
    /// The six tetrahedra, as cube corners: the monotone paths 0, e_a, e_a + e_b, 7 over the
    /// axis orders (a, b, c). Every cube is cut the same way, so neighbouring cubes cut their
    /// shared face along the same diagonal.
    tets: [[u8; 4]; 6],
    triangles: [[Vec<[Edge; 3]>; 16]; 6],
}

impl Cases {
    fn new() -> Self {
        const ORDERS: [[u8; 3]; 6] = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        let tets = ORDERS.map(|[a, b, _]| [0, 1 << a, (1 << a) | (1 << b), 7]);
        let triangles = std::array::from_fn(|t| {
            // The signed volume of (v0, v1, v2, v3) is the sign of the axis order.
            let sigma = parity(&ORDERS[t]);
            std::array::from_fn(|mask| {
                let corner = |m: usize| tets[t][m];
                let (neg, pos): (Vec<usize>, Vec<usize>) =
                    (0..4).partition(|&m| mask & (1 << m) != 0);
                // The winding follows from the signed volume alone: for a triangle cutting
                // the edges from a vertex r, det(p0 - r, p1 - r, p2 - r) is the tetrahedron's
                // signed volume with r first times positive edge fractions, whatever the
                // fractions are, so no position decides it and neighbours agree.
                let edge = |n: usize, p: usize| [corner(n), corner(p)];
                let wind = |tri: [Edge; 3], outward: bool| {
                    if outward {
                        tri
                    } else {
                        [tri[0], tri[2], tri[1]]
                    }
                };
                match (neg.as_slice(), pos.as_slice()) {
                    (&[n], &[j, k, l]) => {
                        let rho = parity(&[n, j, k, l]);
                        vec![wind([edge(n, j), edge(n, k), edge(n, l)], sigma * rho > 0)]
                    }
                    (&[j, k, l], &[o]) => {
                        let rho = parity(&[o, j, k, l]);
                        vec![wind([edge(j, o), edge(k, o), edge(l, o)], sigma * rho < 0)]
                    }
                    (&[a, b], &[c, d]) => {
                        // The quad ac, ad, bd, bc, split along ac-bd; both halves face away
                        // from a and b with the sign of the volume of (a, b, c, d).
                        let out = sigma * parity(&[a, b, c, d]) > 0;
                        vec![
                            wind([edge(a, c), edge(a, d), edge(b, d)], out),
                            wind([edge(a, c), edge(b, d), edge(b, c)], out),
                        ]
                    }
                    _ => Vec::new(),
                }
            })
        });
        Cases { tets, triangles }
    }
}

/// +1 for an even permutation of distinct values, -1 for an odd one.
fn parity<T: PartialOrd>(p: &[T]) -> i32 {
    let mut sign = 1;
    for i in 0..p.len() {
        for j in i + 1..p.len() {
            if p[i] > p[j] {
                sign = -sign;
            }
        }
    }
    sign
}

/// A mesh vertex: its object-space position and shading normal (`None` where the normal is
/// undefined, to fall back to the face normal).
#[derive(Clone, Copy)]
struct Vertex {
    position: Vec3,
    normal: Option<Vec3>,
}

/// One worker's tables for the cell it is meshing, kept between cells.
struct Scratch {
    subdivisions: usize,
    /// The interpolant at the (s+1)^3 sub-cube corners.
    values: Vec<f64>,
    /// Per sub-cube corner and monotone direction (1..=7), the vertex on that edge, valid
    /// when its stamp is the cell's: a vertex is found once and shared by every
    /// tetrahedron around the edge, with no clearing between cells.
    edge_stamp: Vec<u32>,
    edge_vertex: Vec<u32>,
    stamp: u32,
    vertices: Vec<Vertex>,
}

impl Scratch {
    fn new(subdivisions: usize) -> Self {
        let points = (subdivisions + 1).pow(3);
        Scratch {
            subdivisions,
            values: vec![0.0; points],
            edge_stamp: vec![0; points * 7],
            edge_vertex: vec![0; points * 7],
            stamp: 0,
            vertices: Vec::new(),
        }
    }
}

/// The most Newton steps on a diagonal edge. From the secant estimate Newton's method
/// converges quadratically, in two or three steps; bisection, its fallback, halves the
/// bracket 40 times, below what the f32 positions resolve.
const ROOT_ITERATIONS: usize = 40;

/// The zero of the interpolant `corners` on the segment from local `a` (value `fa`) to `b`
/// (`fb`, of the other sign, 0 counting as positive), as a fraction of the way from `a` to
/// `b`.
///
/// Along an axis the interpolant is linear, so the secant is exact; along a diagonal it is a
/// cubic (a quadratic across a face), solved by Newton's method safeguarded by bisection of
/// the bracket the end signs give (as Mitsuba solves the cubic along a ray).
fn edge_root(corners: &[f64; 8], a: DVec3, fa: f64, b: DVec3, fb: f64, axial: bool) -> f64 {
    let mut t = (fa / (fa - fb)).clamp(0.0, 1.0);
    if axial {
        return t;
    }
    let along = b - a;
    let (mut near, mut far) = (0.0, 1.0);
    for _ in 0..ROOT_ITERATIONS {
        let p = a + t * along;
        let f = trilerp(corners, p);
        if f == 0.0 {
            break;
        }
        if (f < 0.0) == (fa < 0.0) {
            near = t;
        } else {
            far = t;
        }
        let step = t - f / trilerp_gradient(corners, p).dot(along);
        // A step out of the bracket (or a NaN from a flat spot) bisects instead.
        let next = if step > near.min(far) && step < near.max(far) {
            step
        } else {
            0.5 * (near + far)
        };
        let done = (next - t).abs() <= 1e-12;
        t = next;
        if done {
            break;
        }
    }
    t
}

/// Appends the triangles of one occupied cell to `out`.
fn mesh_cell(
    field: &Field,
    cases: &Cases,
    mode: SdfNormals,
    cell: [usize; 3],
    scratch: &mut Scratch,
    out: &mut Vec<Triangle>,
) {
    let s = scratch.subdivisions;
    let n1 = s + 1;
    let corners = field.corners(cell);
    // Local coordinates i / s, exactly 0 and 1 on the cell's faces (see `lerp`).
    let local = |i: usize| i as f64 / s as f64;
    for k in 0..n1 {
        for j in 0..n1 {
            for i in 0..n1 {
                scratch.values[i + n1 * (j + n1 * k)] =
                    trilerp(&corners, DVec3::new(local(i), local(j), local(k)));
            }
        }
    }
    scratch.stamp = scratch.stamp.wrapping_add(1);
    if scratch.stamp == 0 {
        scratch.edge_stamp.fill(0);
        scratch.stamp = 1;
    }
    scratch.vertices.clear();
    let offsets: [usize; 8] =
        std::array::from_fn(|b| (b & 1) + n1 * ((b >> 1) & 1) + n1 * n1 * (b >> 2));
    let origin = DVec3::new(cell[0] as f64, cell[1] as f64, cell[2] as f64);

    for k in 0..s {
        for j in 0..s {
            for i in 0..s {
                let base = i + n1 * (j + n1 * k);
                let mut negative = 0u8;
                for (b, &o) in offsets.iter().enumerate() {
                    if scratch.values[base + o] < 0.0 {
                        negative |= 1 << b;
                    }
                }
                if negative == 0 || negative == 0xff {
                    continue;
                }
                let lower = [i, j, k];
                for (t, tet) in cases.tets.iter().enumerate() {
                    let mask =
                        (0..4).fold(0, |m, v| m | (((negative >> tet[v]) & 1) as usize) << v);
                    for tri in &cases.triangles[t][mask] {
                        let ids = tri.map(|[neg, pos]| {
                            // Each edge is keyed by its lower end and direction, the same for
                            // every tetrahedron around it, and solved from that end so that
                            // its neighbours in the next cell solve the same problem.
                            let (lo, hi) = if neg & !pos == 0 {
                                (neg, pos)
                            } else {
                                (pos, neg)
                            };
                            let key = (base + offsets[lo as usize]) * 7 + (hi ^ lo) as usize - 1;
                            if scratch.edge_stamp[key] == scratch.stamp {
                                return scratch.edge_vertex[key];
                            }
                            let corner = |c: u8| {
                                DVec3::new(
                                    local(lower[0] + (c & 1) as usize),
                                    local(lower[1] + ((c >> 1) & 1) as usize),
                                    local(lower[2] + (c >> 2) as usize),
                                )
                            };
                            let (a, b) = (corner(lo), corner(hi));
                            let (fa, fb) = (
                                scratch.values[base + offsets[lo as usize]],
                                scratch.values[base + offsets[hi as usize]],
                            );
                            let root =
                                edge_root(&corners, a, fa, b, fb, (hi ^ lo).count_ones() == 1);
                            let l = a + root * (b - a);
                            let q = origin + l;
                            let normal = match mode {
                                SdfNormals::Analytic => field.gradient(&corners, l),
                                SdfNormals::Smooth => field.smooth(q),
                            }
                            .try_normalize()
                            .map(|n| n.as_vec3());
                            let id = scratch.vertices.len() as u32;
                            scratch.vertices.push(Vertex {
                                position: (q / field.scale).as_vec3(),
                                normal,
                            });
                            scratch.edge_stamp[key] = scratch.stamp;
                            scratch.edge_vertex[key] = id;
                            id
                        });
                        let v = ids.map(|id| scratch.vertices[id as usize]);
                        let p = v.map(|v| v.position);
                        let face = (p[1] - p[0]).cross(p[2] - p[0]);
                        // Samples exactly 0 put vertices on sub-cube corners, where several
                        // edges meet: their triangles collapse.
                        let Some(face) = face.try_normalize() else {
                            continue;
                        };
                        out.push((p, v.map(|v| v.normal.unwrap_or(face))));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn grid(res: [usize; 3], f: impl Fn(DVec3) -> f64) -> VolFile {
        let mut values = Vec::with_capacity(res[0] * res[1] * res[2]);
        for k in 0..res[2] {
            for j in 0..res[1] {
                for i in 0..res[0] {
                    let p = DVec3::new(
                        i as f64 / (res[0] - 1) as f64,
                        j as f64 / (res[1] - 1) as f64,
                        k as f64 / (res[2] - 1) as f64,
                    );
                    values.push(f(p) as f32);
                }
            }
        }
        VolFile {
            res,
            channels: 1,
            bbox: (Vec3::ZERO, Vec3::ONE),
            values,
        }
    }

    /// SplitMix64: reproducible random numbers in [0, 1) without a crate.
    fn uniform(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The piecewise-trilinear field at object point p, written out from the samples.
    fn field_at(vol: &VolFile, p: DVec3) -> f64 {
        let f = Field::new(vol);
        let q = p * f.scale;
        let cell = f.cell_of(q);
        let origin = DVec3::new(cell[0] as f64, cell[1] as f64, cell[2] as f64);
        trilerp(&f.corners(cell), q - origin)
    }

    const CENTRE: DVec3 = DVec3::splat(0.5);
    const RADIUS: f64 = 0.3;

    fn sphere() -> VolFile {
        grid([24; 3], |p| (p - CENTRE).length() - RADIUS)
    }

    #[test]
    fn sdfgrid_sphere_is_a_closed_outward_mesh_on_the_zero_set() {
        let vol = sphere();
        let mesh = sdf_mesh(&vol, SdfNormals::Smooth, 4).unwrap();
        assert!(
            mesh.triangles.len() > 1000,
            "{} triangles",
            mesh.triangles.len()
        );
        assert_eq!(mesh.triangles.len(), mesh.normals.len());
        let cell = 1.0 / 23.0;

        let mut worst_value: f64 = 0.0;
        let mut worst_angle: f64 = 0.0;
        let mut area = 0.0;
        let mut edges: HashMap<([u32; 3], [u32; 3]), i32> = HashMap::new();
        for (tri, normals) in mesh.triangles.iter().zip(&mesh.normals) {
            let d = tri.map(|p| p.as_dvec3());
            let cross = (d[1] - d[0]).cross(d[2] - d[0]);
            area += 0.5 * cross.length();
            let centroid = (d[0] + d[1] + d[2]) / 3.0;
            assert!(
                cross.dot(centroid - CENTRE) > 0.0,
                "inward triangle {tri:?}"
            );
            for (p, n) in d.iter().zip(normals) {
                worst_value = worst_value.max(field_at(&vol, *p).abs());
                let radial = (*p - CENTRE).normalize();
                let n = n.as_dvec3();
                assert!((n.length() - 1.0).abs() < 1e-5);
                worst_angle = worst_angle.max(n.dot(radial).clamp(-1.0, 1.0).acos().to_degrees());
            }
            for e in 0..3 {
                let (a, b) = (
                    tri[e].to_array().map(f32::to_bits),
                    tri[(e + 1) % 3].to_array().map(f32::to_bits),
                );
                // +1 for a -> b and -1 for b -> a, keyed by the unordered pair.
                let (key, dir) = if a < b { ((a, b), 1) } else { ((b, a), -1) };
                let entry = edges.entry(key).or_insert(0);
                *entry += dir * 100 + 1;
            }
        }
        assert!(
            worst_value < 1e-4 * cell,
            "a vertex is {worst_value} off the zero set"
        );
        // Each edge used once each way: +1 -1 in direction, 2 in count.
        let open = edges.values().filter(|&&v| v != 2).count();
        assert_eq!(
            open,
            0,
            "{open} of {} edges are not shared by two opposite triangles",
            edges.len()
        );
        let sphere_area = 4.0 * std::f64::consts::PI * RADIUS * RADIUS;
        assert!(
            (area / sphere_area - 1.0).abs() < 0.01,
            "area {area} against {sphere_area}"
        );
        assert!(
            worst_angle < 1.0,
            "a smooth normal is {worst_angle} degrees off radial"
        );
    }

    #[test]
    fn sdfgrid_analytic_normals_are_the_cells_gradient() {
        let mut rng = 7;
        let vol = grid([5, 4, 6], |_| 0.0);
        let values: Vec<f32> = vol
            .values
            .iter()
            .map(|_| (uniform(&mut rng) - 0.5) as f32)
            .collect();
        let vol = VolFile { values, ..vol };
        let field = Field::new(&vol);
        // The interpolant of one cell at an object point, extrapolated beyond it.
        let in_cell = |cell: [usize; 3], p: DVec3| {
            let origin = DVec3::new(cell[0] as f64, cell[1] as f64, cell[2] as f64);
            trilerp(&field.corners(cell), p * field.scale - origin)
        };
        let difference = |cell: [usize; 3], p: DVec3| {
            let h = 1e-4;
            DVec3::new(
                in_cell(cell, p + DVec3::X * h) - in_cell(cell, p - DVec3::X * h),
                in_cell(cell, p + DVec3::Y * h) - in_cell(cell, p - DVec3::Y * h),
                in_cell(cell, p + DVec3::Z * h) - in_cell(cell, p - DVec3::Z * h),
            ) / (2.0 * h)
        };
        for _ in 0..200 {
            let p = DVec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng));
            let q = p * field.scale;
            let cell = field.cell_of(q);
            let origin = DVec3::new(cell[0] as f64, cell[1] as f64, cell[2] as f64);
            let analytic = field.gradient(&field.corners(cell), q - origin);
            let expected = difference(cell, p);
            assert!(
                (analytic - expected).length() < 1e-6 * expected.length().max(1.0),
                "at {p}: {analytic} against {expected}"
            );
        }
        // On the mesh: each corner's normal is its own cell's normalised gradient, checked
        // where the corner is strictly inside one cell.
        let mesh = sdf_mesh(&vol, SdfNormals::Analytic, 3).unwrap();
        let mut checked = 0;
        for (tri, normals) in mesh.triangles.iter().zip(&mesh.normals) {
            for (p, n) in tri.iter().zip(normals) {
                let q = p.as_dvec3() * field.scale;
                if q.to_array().iter().any(|c| (c - c.round()).abs() < 1e-3) {
                    continue;
                }
                let expected = difference(field.cell_of(q), p.as_dvec3()).normalize();
                assert!(
                    (n.as_dvec3() - expected).length() < 1e-4,
                    "at {p}: {n} against {expected}"
                );
                checked += 1;
            }
        }
        assert!(checked > 100, "only {checked} corners checked");
    }

    /// The gradient of cell `lower` of the samples at its corner `vertex`, differences of
    /// samples along the cell's edges from that corner, in object units.
    fn corner_gradient(vol: &VolFile, lower: [usize; 3], vertex: [usize; 3]) -> DVec3 {
        let at = |i: [usize; 3]| vol.values[(i[2] * vol.res[1] + i[1]) * vol.res[0] + i[0]] as f64;
        let mut g = [0.0; 3];
        for a in 0..3 {
            let (mut from, mut to) = (vertex, vertex);
            from[a] = lower[a];
            to[a] = lower[a] + 1;
            g[a] = (at(to) - at(from)) * (vol.res[a] - 1) as f64;
        }
        DVec3::from_array(g)
    }

    #[test]
    fn sdfgrid_smooth_normal_at_a_lattice_vertex_is_the_mean_of_eight_cells() {
        let mut rng = 11;
        let vol = grid([6, 7, 8], |p| (p - CENTRE).length() - 0.35);
        let values: Vec<f32> = vol
            .values
            .iter()
            .map(|v| v + 0.05 * (uniform(&mut rng) - 0.5) as f32)
            .collect();
        let vol = VolFile { values, ..vol };
        let field = Field::new(&vol);
        let vertex = [3, 2, 5];
        let mut mean = DVec3::ZERO;
        for o in 0..8 {
            let lower = [
                vertex[0] + (o & 1) - 1,
                vertex[1] + ((o >> 1) & 1) - 1,
                vertex[2] + (o >> 2) - 1,
            ];
            mean += corner_gradient(&vol, lower, vertex).normalize() / 8.0;
        }
        let q = DVec3::new(vertex[0] as f64, vertex[1] as f64, vertex[2] as f64);
        let smooth = field.smooth(q).normalize();
        assert!(
            (smooth - mean.normalize()).length() < 1e-12,
            "{smooth} against {}",
            mean.normalize()
        );

        // On the lower x face only the four cells above it count.
        let vertex = [0, 2, 5];
        let mut mean = DVec3::ZERO;
        for o in 0..4 {
            let lower = [0, vertex[1] + (o & 1) - 1, vertex[2] + (o >> 1) - 1];
            mean += corner_gradient(&vol, lower, vertex).normalize() / 4.0;
        }
        let q = DVec3::new(0.0, 2.0, 5.0);
        let smooth = field.smooth(q).normalize();
        assert!(
            (smooth - mean.normalize()).length() < 1e-12,
            "{smooth} against {}",
            mean.normalize()
        );

        // On the upper x face Mitsuba keeps the cells beyond it, with no x difference.
        let vertex = [5, 2, 5];
        let mut mean = DVec3::ZERO;
        for o in 0..8 {
            let (y, z) = (vertex[1] + ((o >> 1) & 1) - 1, vertex[2] + (o >> 2) - 1);
            let g = if o & 1 == 0 {
                corner_gradient(&vol, [4, y, z], vertex)
            } else {
                corner_gradient(&vol, [4, y, z], vertex) * DVec3::new(0.0, 1.0, 1.0)
            };
            mean += g.normalize() / 8.0;
        }
        let smooth = field.smooth(DVec3::new(5.0, 2.0, 5.0)).normalize();
        assert!(
            (smooth - mean.normalize()).length() < 1e-12,
            "{smooth} against {}",
            mean.normalize()
        );
    }

    #[test]
    fn sdfgrid_refuses_grids_without_a_surface_or_with_bad_values() {
        let sphere = sphere();
        let err = |vol: &VolFile, s: usize| sdf_mesh(vol, SdfNormals::Smooth, s).unwrap_err();

        let three = VolFile {
            channels: 3,
            values: sphere.values.iter().flat_map(|&v| [v; 3]).collect(),
            ..sphere.clone()
        };
        assert!(
            err(&three, 2).contains("one channel, the file has 3"),
            "{}",
            err(&three, 2)
        );

        let positive = grid([4; 3], |p| p.x + 1.0);
        assert!(
            err(&positive, 2).contains("every value has the same sign"),
            "{}",
            err(&positive, 2)
        );

        let flat = grid([4, 1, 4], |_| 0.0);
        let flat = VolFile {
            values: vec![0.0; 16],
            ..flat
        };
        assert!(
            err(&flat, 2).contains("at least 2 samples along each axis, the file has 1 along y"),
            "{}",
            err(&flat, 2)
        );

        let mut nan = sphere.clone();
        nan.values[24 * 24 * 3 + 24 * 2 + 1] = f32::NAN;
        assert!(
            err(&nan, 2).contains("(1, 2, 3) is NaN"),
            "{}",
            err(&nan, 2)
        );

        assert!(
            err(&sphere, 0).contains("subdivisions 0"),
            "{}",
            err(&sphere, 0)
        );
    }

    /// Grids with values replaced by extremes (huge, tiny, zero, of either sign): a mesh or
    /// an error, never a panic, and every vertex finite. FOTON_FUZZ_SDF cases (300).
    #[test]
    fn sdfgrid_extreme_values_are_meshes_or_errors() {
        let n = std::env::var("FOTON_FUZZ_SDF")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(300);
        let extremes = [0.0f32, -0.0, 1e30, -1e30, 1e-30, -1e-30, f32::MAX, f32::MIN];
        let mut state = 5u64;
        let mut outcomes = [0usize; 2];
        for _ in 0..n {
            let res = [2 + (uniform(&mut state) * 5.0) as usize, 3, 4];
            let mut vol = grid(res, |p| (p - CENTRE).length() - RADIUS);
            for _ in 0..1 + (uniform(&mut state) * 6.0) as usize {
                let at = (uniform(&mut state) * vol.values.len() as f64) as usize;
                vol.values[at] = extremes[(uniform(&mut state) * extremes.len() as f64) as usize];
            }
            let normals = if uniform(&mut state) < 0.5 {
                SdfNormals::Smooth
            } else {
                SdfNormals::Analytic
            };
            let result = std::panic::catch_unwind(|| sdf_mesh(&vol, normals, 2));
            match result {
                Ok(Ok(mesh)) => {
                    outcomes[1] += 1;
                    assert!(
                        mesh.triangles.iter().flatten().all(|v| v.is_finite())
                            && mesh.normals.iter().flatten().all(|v| v.is_finite()),
                        "a vertex or normal is not finite: {:?}",
                        vol.values
                    );
                }
                Ok(Err(_)) => outcomes[0] += 1,
                Err(_) => panic!("panicked on {:?}", vol.values),
            }
        }
        assert!(outcomes[1] > n / 10, "errors, meshes: {outcomes:?}");
    }
}
