//! How `foton compare --time S` gives each integrator about S seconds: short calibration
//! renders measure a fixed cost (a photon pass) and a cost per step, and a [`Plan`] turns them
//! into the scene values (`--set` overrides) that fill S; and the budgets of `--curve`.

use super::Session;
use crate::common::{INTERRUPTED, Prepared};
use foton_core::error::Result;
use foton_core::film::Film;
use foton_core::integrator::{Budget, Work};
use std::io::Write;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// The cost of a render as a function of its budget n (samples per pixel, or iterations of a
/// progressive integrator), t(n) = fixed + n x per_unit, from the times t1 and t2 of renders
/// at n and 2n.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CostModel {
    /// Seconds that do not grow with n (a photon mapper's photon pass).
    pub fixed: f64,
    pub per_unit: f64,
    /// The time of the longer calibration render (t2).
    pub longest: f64,
}

impl CostModel {
    /// per_unit = (t2 - t1) / n, bounded to [t2/20, t2/2] / n so that timer noise on a fast
    /// render cannot ask for an enormous budget; fixed = t2 - 2n per_unit.
    pub fn from_times(n: u32, t1: f64, t2: f64) -> CostModel {
        let n = n.max(1) as f64;
        let t2 = t2.max(1e-6);
        let per_unit = ((t2 - t1) / n).clamp(t2 / 20.0 / n, t2 / 2.0 / n);
        CostModel {
            fixed: (t2 - 2.0 * n * per_unit).max(0.0),
            per_unit,
            longest: t2,
        }
    }

    /// The budget n that fills `seconds`, at least 1.
    pub fn units_for(&self, seconds: f64) -> u32 {
        ((seconds - self.fixed) / self.per_unit)
            .floor()
            .clamp(1.0, u32::MAX as f64) as u32
    }
}

/// Calibration renders take at least this long (or a tenth of the budget, if that is less),
/// so that their times are not timer and scheduler noise.
pub const CALIBRATION_SECONDS: f64 = 0.05;

/// The most units `calibrate_cost` renders at (n; the second render is at 2n).
pub(crate) const MAX_UNITS: u32 = 1 << 16;

/// The cost model from renders at n and 2n units, n = 1 and then larger until the render at
/// 2n takes `min_seconds` (n at most `max_units`, at least 1). `seconds_of(n)` renders at n
/// and returns its time.
pub(crate) fn calibrate_cost(
    min_seconds: f64,
    max_units: u32,
    mut seconds_of: impl FnMut(u32) -> Result<f64>,
) -> Result<CostModel> {
    let max_units = max_units.max(1);
    let mut n = 1u32;
    loop {
        let t1 = seconds_of(n)?;
        let t2 = seconds_of(2 * n)?;
        if t2 >= min_seconds || n >= max_units || INTERRUPTED.load(Ordering::SeqCst) {
            return Ok(CostModel::from_times(n, t1, t2));
        }
        let factor = (min_seconds / t2.max(1e-6)).ceil().clamp(2.0, 1024.0) as u32;
        n = n.saturating_mul(factor).min(max_units);
    }
}

/// Samples per pixel that fill `budget` seconds, from the times of renders at 1 and 2 spp
/// (see `CostModel`).
pub fn spp_for_budget(budget: f64, t1: f64, t2: f64) -> u32 {
    CostModel::from_times(1, t1, t2).units_for(budget)
}

/// How `--time` gives an integrator a budget of S seconds, from its calibration renders.
#[derive(Clone, Debug, PartialEq)]
pub enum Plan {
    /// Samples per pixel (render.spp) fill the time.
    Samples(CostModel),
    /// A progressive integrator (its `Integrator::budget` counts iterations, sppm): the scene
    /// value at `key` fills the time; render.spp is not used.
    Iterations { cost: CostModel, key: String },
    /// An integrator with budgets that scale beside its samples (`Integrator::budget`'s
    /// `scaled`: a photon mapper's photon budgets): about half of the time goes to their fixed
    /// cost, half to camera samples. The scene's budgets are taken to belong to the time 2 x
    /// `photon_pass` (the measured fixed cost) and are scaled in proportion to the budget;
    /// spp = (S / 2) / `per_sample`.
    PhotonsAndSamples {
        per_sample: f64,
        photon_pass: f64,
        photons: Vec<(String, u64)>,
    },
    /// A budget that --time cannot set: the calibration render is the render.
    Fixed,
}

impl Plan {
    /// The scene values (`--set` overrides) that make the integrator take about `seconds`.
    pub fn settings(&self, seconds: f64) -> Vec<String> {
        match self {
            Plan::Samples(cost) => vec![format!("render.spp={}", cost.units_for(seconds))],
            Plan::Iterations { cost, key } => vec![format!("{key}={}", cost.units_for(seconds))],
            Plan::PhotonsAndSamples {
                per_sample,
                photon_pass,
                photons,
            } => {
                let half = seconds / 2.0;
                let spp = (half / per_sample).floor().clamp(1.0, u32::MAX as f64) as u32;
                let scale = half / photon_pass;
                let mut sets = vec![format!("render.spp={spp}")];
                for (key, n) in photons {
                    let scaled = if *n == 0 {
                        0
                    } else {
                        (*n as f64 * scale).round().clamp(1.0, 1e15) as u64
                    };
                    sets.push(format!("{key}={scaled}"));
                }
                sets
            }
            Plan::Fixed => Vec::new(),
        }
    }
}

/// "16 spp", "23 iterations" (a progressive integrator's iterations, as --time set them or
/// as its parameters say), or "own budget".
pub(super) fn budget_text(p: &Prepared, settings: &[String]) -> String {
    match p.integrator.budget().work {
        Work::Samples => format!("{} spp", p.scene.render().spp),
        Work::Iterations { key } => {
            let set = settings
                .iter()
                .find_map(|s| s.strip_prefix(&format!("{key}=")).map(str::to_string));
            let name = key.rsplit('.').next().unwrap_or(&key);
            let given = || {
                p.integrator
                    .parameters()
                    .into_iter()
                    .find(|q| q.name == name)
                    .map(|q| q.value.to_string())
            };
            match set.or_else(given) {
                Some(n) => format!("{n} iterations"),
                None => "own budget".into(),
            }
        }
        Work::Own => "own budget".into(),
    }
}

/// Calibrates how `--time` sets integrator `name`'s budget (see `Plan`), from what the
/// integrator says of its work (`Integrator::budget`): renders at n and 2n samples per pixel,
/// or iterations of a progressive integrator (`calibrate_cost`). With `Plan::Fixed` (a budget
/// of its own), also returns the one render made, which is then the render shown.
pub(super) fn calibrate(
    session: &Session,
    name: &str,
    p: &mut Prepared,
    budget: f64,
    err: &mut dyn Write,
) -> Result<(Plan, Option<(Film, Duration)>)> {
    let min_seconds = CALIBRATION_SECONDS.min(budget / 10.0);
    let Budget { work, scaled } = p.integrator.budget();
    match work {
        Work::Iterations { key } => {
            let cost = calibrate_cost(min_seconds, MAX_UNITS, |n| {
                let q = session.prepare(name, &[format!("{key}={n}")])?;
                Ok(session.render(&q, true, err)?.1.as_secs_f64())
            })?;
            let _ = writeln!(
                err,
                "note: `{name}` does not take its samples from render.spp: --time sets its iterations instead ({key})"
            );
            Ok((Plan::Iterations { cost, key }, None))
        }
        Work::Own => {
            let _ = writeln!(
                err,
                "warning: `{name}` sets its own budget, so --time cannot set it; it renders as the scene says"
            );
            let shown = session.render(p, true, err)?;
            Ok((Plan::Fixed, Some(shown)))
        }
        Work::Samples => {
            let cost = calibrate_cost(min_seconds, MAX_UNITS, |n| {
                p.scene.render_mut().spp = n;
                Ok(session.render(p, true, err)?.1.as_secs_f64())
            })?;
            let plan = if scaled.is_empty() {
                Plan::Samples(cost)
            } else {
                Plan::PhotonsAndSamples {
                    per_sample: cost.per_unit,
                    // Not below the bound of the per-sample cost: noise on a fast photon pass
                    // would otherwise ask for an enormous number of photons.
                    photon_pass: cost.fixed.max(cost.longest / 20.0),
                    photons: scaled,
                }
            };
            Ok((plan, None))
        }
    }
}

/// The budgets of the error curve: `points` times from `budget` / 2^(points - 1) to `budget`,
/// each twice the one before.
pub fn curve_budgets(budget: f64, points: u32) -> Vec<f64> {
    (0..points)
        .map(|j| budget / 2f64.powi((points - 1 - j) as i32))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budget_is_filled_and_fixed_costs_are_not_counted_per_sample() {
        // 1 s of photon pass, 1/8 s per sample: 10 s fit 72 samples.
        assert_eq!(spp_for_budget(10.0, 1.125, 1.25), 72);
        // Pure per-sample cost.
        assert_eq!(spp_for_budget(8.0, 0.5, 1.0), 16);
        // A noisy, faster second render does not ask for millions of samples.
        let spp = spp_for_budget(1.0, 0.02, 0.01);
        assert!((1000..=2000).contains(&spp), "{spp}");
        assert_eq!(spp_for_budget(0.001, 1.0, 2.0), 1);
    }

    #[test]
    fn photon_budgets_and_samples_grow_with_the_time() {
        // A photon pass of 0.5 s at the scene's budgets, 0.05 s per sample per pixel: the
        // scene's budgets belong to 1 s; 10 s gets ten times the photons and 100 spp.
        let plan = Plan::PhotonsAndSamples {
            per_sample: 0.05,
            photon_pass: 0.5,
            photons: vec![
                ("integrators.photon.global_photons".into(), 200_000),
                ("integrators.photon.caustic_photons".into(), 0),
            ],
        };
        assert_eq!(
            plan.settings(10.0),
            [
                "render.spp=100",
                "integrators.photon.global_photons=2000000",
                "integrators.photon.caustic_photons=0"
            ]
        );
        assert_eq!(
            plan.settings(0.01)[..2],
            ["render.spp=1", "integrators.photon.global_photons=2000"]
        );
        let cost = CostModel::from_times(1, 1.125, 1.25);
        assert_eq!(
            Plan::Iterations {
                cost,
                key: "integrators.sppm.iterations".into()
            }
            .settings(10.0),
            ["integrators.sppm.iterations=72"]
        );
        assert_eq!(Plan::Samples(cost).settings(10.0), ["render.spp=72"]);
    }

    #[test]
    fn curve_budgets_double_up_to_the_time() {
        assert_eq!(curve_budgets(20.0, 5), [1.25, 2.5, 5.0, 10.0, 20.0]);
        assert_eq!(curve_budgets(1.0, 2), [0.5, 1.0]);
    }
}
