//! `heterogeneous`: a medium whose density (and albedo) vary over space, given on grids
//! (Mitsuba's `heterogeneous` medium with `gridvolume`s, pbrt-v4's `uniformgrid`).
//!
//! sigma_t(p) = `sigma_t` density(p), sigma_s(p) = albedo(p) sigma_t(p) and
//! sigma_a(p) = (1 - albedo(p)) sigma_t(p), with density and albedo trilinearly interpolated.
//! Transmittance and free-flight distances are exact (see `grid.rs`): no estimator of this
//! medium adds noise of its own, and every pdf an integrator asks for is the true one.
//!
//! | Parameter | Type                     | Meaning                                    | Default        |
//! |-----------|--------------------------|--------------------------------------------|----------------|
//! | `density` | number or volume table   | extinction per unit `sigma_t`              | required       |
//! | `sigma_t` | RGB or number (1/m)      | extinction at density 1                    | `[1, 1, 1]`    |
//! | `albedo`  | RGB or volume table      | single-scattering albedo                   | `[0.75, 0.75, 0.75]` |
//! | `phase`   | string/table             | `"isotropic"` or `{ type = "hg", g = ... }`| `"isotropic"`  |
//! | `emission`| RGB, number or volume table | emitted radiance Le (W m^-2 sr^-1): sigma_a Le per metre along a ray | none |
//!
//! A volume table is `{ file = "smoke.vol" }` (Mitsuba's binary grid) or
//! `{ resolution = [nx, ny, nz], values = [...] }` (x fastest, then y, then z; three values per
//! sample for an RGB albedo), with `transform` (the grid's unit cube into the scene; the
//! identity when absent), `samples` (`"centres"`: sample i at (i + 1/2) / n, as Mitsuba 3 and
//! pbrt-v4; `"corners"`: at i / (n - 1), as Mitsuba 0.6) and `outside` (`"clamp"`: the nearest
//! sample; `"zero"`, as Mitsuba 0.6; `"box"`: the nearest sample within the axis-aligned box
//! around the grid's unit cube, zero beyond, as Mitsuba 3's medium, which exists only in
//! its extinction volume's box; `"repeat"`, an albedo or emission only: the grid tiles space,
//! as Mitsuba 3's `repeat` wrap mode).

use super::grid::{Grid, Outside, Samples, VolFile};
use super::{FreeFlight, Medium, Phase};
use crate::Rgb;
use crate::error::Result;
use crate::geometry::Ray;
use crate::props::Properties;
use crate::registry::{Factory, Resources};
use crate::value::Value;
use glam::{Mat4, Vec3};

/// A colour the same everywhere or on a grid (the albedo, the emission).
#[derive(Clone, Debug)]
pub enum Field {
    Constant(Rgb),
    Grid(Grid),
}

/// The single-scattering albedo (clamped to [0, 1] where it is looked up).
pub type Albedo = Field;

impl Field {
    #[inline]
    fn at(&self, p: Vec3) -> Rgb {
        match self {
            Field::Constant(a) => *a,
            Field::Grid(g) => g.lookup(p),
        }
    }
}

/// A medium of spatially varying density and albedo, which may emit.
#[derive(Clone, Debug)]
pub struct Heterogeneous {
    pub density: Grid,
    pub sigma_t: Rgb,
    pub albedo: Albedo,
    pub phase: Phase,
    /// Emitted radiance Le; None where the medium does not emit.
    pub emission: Option<Field>,
}

impl Heterogeneous {
    fn extinction(&self, p: Vec3) -> Rgb {
        self.sigma_t * self.density.lookup(p)
    }

    #[inline]
    fn albedo(&self, p: Vec3) -> Rgb {
        self.albedo.at(p).min(Rgb::ONE)
    }
}

impl Medium for Heterogeneous {
    fn is_vacuum(&self) -> bool {
        self.density.max() == 0.0 || self.sigma_t.max_element() == 0.0
    }
    fn sigma_a(&self, p: Vec3) -> Rgb {
        self.extinction(p) * (Rgb::ONE - self.albedo(p))
    }
    fn sigma_s(&self, p: Vec3) -> Rgb {
        self.extinction(p) * self.albedo(p)
    }
    fn sigma_t(&self, p: Vec3) -> Rgb {
        self.extinction(p)
    }
    fn phase(&self) -> Phase {
        self.phase
    }
    fn emission(&self, p: Vec3) -> Rgb {
        self.emission.as_ref().map_or(Rgb::ZERO, |e| e.at(p))
    }
    fn is_emissive(&self) -> bool {
        self.emission.is_some()
    }
    /// exp(-sigma_t D), D the integral of the density along the segment.
    fn transmittance(&self, ray: &Ray, d: f32) -> Rgb {
        transmittance_of(self.sigma_t, self.density.integral(ray, d))
    }
    /// t is drawn from sigma_t,c(t) exp(-int_0^t sigma_t,c) for the given channel c, by
    /// inverting the optical depth.
    fn sample_free_flight(&self, ray: &Ray, tmax: f32, channel: usize, u: f32) -> FreeFlight {
        let s = self.sigma_t[channel];
        let (t, depth) = if s > 0.0 {
            // 1 - u is in (0, 1]: the target depth is finite.
            let target = -((1.0 - u as f64).ln()) / s as f64;
            self.density.invert(ray, tmax, channel, target)
        } else {
            (None, self.density.integral(ray, tmax))
        };
        let tr = transmittance_of(self.sigma_t, depth);
        match t {
            Some(t) if (t as f32) < tmax => {
                let t = t as f32;
                let p = ray.at(t);
                let sigma_t = self.extinction(p);
                let albedo = self.albedo(p);
                let emitted = match &self.emission {
                    Some(e) => sigma_t * (Rgb::ONE - albedo) * e.at(p) * tr,
                    None => Rgb::ZERO,
                };
                FreeFlight {
                    t,
                    scattered: true,
                    f: sigma_t * albedo * tr,
                    pdf: sigma_t * tr,
                    emitted,
                }
            }
            _ => FreeFlight {
                t: tmax,
                scattered: false,
                f: tr,
                pdf: tr,
                emitted: Rgb::ZERO,
            },
        }
    }
}

/// exp(-sigma_t,c D_c) per channel, D the density's integral; a channel with sigma_t = 0
/// or D = 0 transmits fully (0 x inf would be NaN).
fn transmittance_of(sigma_t: Rgb, depth: glam::DVec3) -> Rgb {
    let tr = |s: f32, d: f64| {
        if s == 0.0 || d == 0.0 {
            1.0
        } else {
            (-(s as f64) * d).exp() as f32
        }
    };
    Rgb::new(
        tr(sigma_t.x, depth.x),
        tr(sigma_t.y, depth.y),
        tr(sigma_t.z, depth.z),
    )
}

/// A volume parameter: a number (the same everywhere) or a volume table (see the module
/// comment); `channels` are the channel counts allowed. None where `key` is not a table.
pub fn volume<'a>(
    m: &Properties<'a>,
    key: &str,
    channels: &[usize],
    nested: &mut Vec<Properties<'a>>,
    res: &mut dyn Resources,
) -> Result<Option<Grid>> {
    if !matches!(m.node(key).map(|n| &n.value), Some(Value::Table(_))) {
        return Ok(None);
    }
    let Some(v) = m.table(key)? else {
        return Ok(None);
    };
    let (size, count, values) = if v.has("file") {
        if v.has("values") || v.has("resolution") {
            return Err(v.error(
                "file",
                "a volume is either `file` or `resolution` and `values`, not both",
            ));
        }
        let bytes = res.file(&v, "file")?;
        let f = VolFile::parse(&bytes).map_err(|e| v.error("file", e))?;
        (f.res, f.channels, f.values)
    } else {
        let r = v.floats_opt("resolution", 3)?.ok_or_else(|| {
            v.error(
                "resolution",
                "missing: a volume table gives `file`, or `resolution` and `values`",
            )
        })?;
        if r.iter().any(|x| *x < 1.0 || x.fract() != 0.0) {
            return Err(v.error("resolution", "expected three whole numbers, each at least 1"));
        }
        let size = [r[0] as usize, r[1] as usize, r[2] as usize];
        let samples = size[0] * size[1] * size[2];
        let n = match v.node("values").map(|n| &n.value) {
            Some(Value::Array(items)) => items.len(),
            _ => samples,
        };
        let c = if n == 3 * samples && channels.contains(&3) { 3 } else { 1 };
        let values = v.floats_opt("values", samples * c)?.ok_or_else(|| {
            v.error("values", format!("missing: expected {} numbers", samples * c))
        })?;
        (size, c, values)
    };
    if !channels.contains(&count) {
        return Err(v.error(
            if v.has("file") { "file" } else { "values" },
            format!("{count} channels; `{key}` takes {channels:?}"),
        ));
    }
    let to_world: Mat4 = res.transform(&v, "transform")?;
    let samples = match v.choice("samples", &["centres", "corners"], "centres")? {
        "corners" => Samples::Corners,
        _ => Samples::Centres,
    };
    let outside = match v.choice("outside", &["clamp", "zero", "box", "repeat"], "clamp")? {
        "zero" => Outside::Zero,
        "box" => Outside::ClampInBox,
        "repeat" if key == "density" => {
            return Err(v.error(
                "outside",
                "\"repeat\" is for an albedo or an emission: a density must be bounded (clamp, zero or box)",
            ));
        }
        "repeat" => Outside::Repeat,
        _ => Outside::Clamp,
    };
    let grid = Grid::new(size, count, values, to_world, samples, outside)
        .map_err(|e| v.error(if v.has("file") { "file" } else { "values" }, e))?;
    nested.push(v);
    Ok(Some(grid))
}

pub const FACTORY: Factory<dyn Medium> = Factory {
    name: "heterogeneous",
    description: "density and albedo on grids (Mitsuba's .vol files or inline), exact tracking",
    create: |m, nested, res| {
        let density = match volume(m, "density", &[1, 3], nested, res)? {
            Some(g) => g,
            None => {
                let d = m.f32_opt("density")?.ok_or_else(|| {
                    m.error("density", "missing: a number or a volume table")
                })?;
                if d < 0.0 {
                    return Err(m.error("density", "must not be negative"));
                }
                Grid::new([1; 3], 1, vec![d], Mat4::IDENTITY, Samples::Centres, Outside::Clamp)
                    .map_err(|e| m.error("density", e))?
            }
        };
        let sigma_t = match m.node("sigma_t").map(|n| &n.value) {
            Some(Value::Array(_)) => m.rgb("sigma_t", Rgb::ONE)?,
            _ => Rgb::splat(m.f32("sigma_t", 1.0)?),
        };
        if sigma_t.min_element() < 0.0 {
            return Err(m.error("sigma_t", "must not be negative"));
        }
        let albedo = match volume(m, "albedo", &[1, 3], nested, res)? {
            Some(g) => Albedo::Grid(g),
            None => {
                let a = match m.node("albedo").map(|n| &n.value) {
                    Some(Value::Array(_)) | None => m.rgb("albedo", Rgb::splat(0.75))?,
                    _ => Rgb::splat(m.f32("albedo", 0.75)?),
                };
                if a.min_element() < 0.0 || a.max_element() > 1.0 {
                    return Err(m.error("albedo", "each channel must be in [0, 1]"));
                }
                Albedo::Constant(a)
            }
        };
        let phase = Phase::read(m, nested)?;
        let emission = match volume(m, "emission", &[1, 3], nested, res)? {
            Some(g) if g.max() > 0.0 => Some(Field::Grid(g)),
            Some(_) => None,
            None => {
                let e = match m.node("emission").map(|n| &n.value) {
                    Some(Value::Array(_)) | None => m.rgb("emission", Rgb::ZERO)?,
                    _ => Rgb::splat(m.f32("emission", 0.0)?),
                };
                if e.min_element() < 0.0 {
                    return Err(m.error("emission", "must not be negative"));
                }
                (e != Rgb::ZERO).then_some(Field::Constant(e))
            }
        };
        Ok(Box::new(Heterogeneous {
            density,
            sigma_t,
            albedo,
            phase,
            emission,
        }))
    },
};
