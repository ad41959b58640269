//! `render.time`: a time limit in seconds (Mitsuba's `timeout`). Short renders measure what a
//! camera sample per pixel (or an iteration of a progressive integrator) costs, as
//! `foton compare --time` does, and the render takes as many as fill the limit, at most the
//! scene's. The image is then the one the scene renders with that number written out: the
//! same for a seed whatever the threads, though another machine may choose another number.

use crate::common::{INTERRUPTED, Prepared, render_with};
use crate::compare::budget::{CALIBRATION_SECONDS, CostModel, MAX_UNITS, calibrate_cost};
use crate::progress::TermProgress;
use foton_core::error::Result;
use foton_core::integrator::{Budget, RenderContext, Work};

/// What [`fit`] chose.
#[derive(Debug, PartialEq)]
pub enum Fitted {
    /// The scene's camera samples per pixel, now `spp`.
    Samples { spp: u32 },
    /// A progressive integrator's iterations: the scene value `set` (`key=n`) chooses them;
    /// the caller prepares the scene again with it.
    Iterations { set: String, n: u64 },
    /// The integrator sets its own budget: the limit cannot apply.
    Own,
}

impl Fitted {
    /// "371 spp", "23 iterations".
    pub fn text(&self) -> String {
        match self {
            Fitted::Samples { spp } => format!("{spp} spp"),
            Fitted::Iterations { n, .. } => format!("{n} iterations"),
            Fitted::Own => "the integrator's own budget".into(),
        }
    }

    /// The scene value that renders the same image without the limit.
    pub fn set(&self) -> Option<String> {
        match self {
            Fitted::Samples { spp } => Some(format!("render.spp={spp}")),
            Fitted::Iterations { set, .. } => Some(set.clone()),
            Fitted::Own => None,
        }
    }
}

/// The number of units that fill `seconds` under `cost`, at most `most`.
fn units(cost: &CostModel, seconds: f64, most: u64) -> u64 {
    u64::from(cost.units_for(seconds)).min(most).max(1)
}

/// Fits `p`'s work to `seconds` (see the module): sets its spp in place, or says which
/// iterations to prepare it with (`prepare(overrides)` makes the calibration renders'
/// scenes). Renders on `threads` threads, quietly.
pub fn fit(
    p: &mut Prepared,
    seconds: f64,
    threads: usize,
    prepare: &dyn Fn(&[String]) -> Result<Prepared>,
) -> Result<Fitted> {
    let progress = TermProgress::new(true);
    let ctx = RenderContext::new(threads, &INTERRUPTED, &progress);
    // Calibration renders of a tenth of the limit measure the per-unit cost past the fixed
    // costs of a short render (threads, film); the render gets the time they leave.
    let min_seconds = CALIBRATION_SECONDS.max(seconds / 10.0);
    let start = std::time::Instant::now();
    let left = |start: std::time::Instant| (seconds - start.elapsed().as_secs_f64()).max(0.0);
    let Budget { work, .. } = p.integrator.budget();
    match work {
        Work::Samples => {
            let most = p.scene.render().spp;
            // Renders up to the scene's count at most (2n <= spp): a count that fits in the
            // limit is rendered as it is.
            let cost = calibrate_cost(min_seconds, (most / 2).min(MAX_UNITS), |n| {
                p.scene.render_mut().spp = n;
                Ok(render_with(p, &ctx)?.1.as_secs_f64())
            })?;
            let spp = units(&cost, left(start), most.into()) as u32;
            p.scene.render_mut().spp = spp;
            Ok(Fitted::Samples { spp })
        }
        Work::Iterations { key } => {
            let name = key.rsplit('.').next().unwrap_or(&key);
            let most = (p.integrator.parameters().into_iter())
                .find(|q| q.name == name)
                .and_then(|q| q.value.to_string().parse::<u64>().ok())
                .unwrap_or(u64::MAX);
            let cap = u32::try_from(most / 2).unwrap_or(u32::MAX).min(MAX_UNITS);
            let cost = calibrate_cost(min_seconds, cap, |n| {
                let q = prepare(&[format!("{key}={n}")])?;
                Ok(render_with(&q, &ctx)?.1.as_secs_f64())
            })?;
            let n = units(&cost, left(start), most);
            Ok(Fitted::Iterations {
                set: format!("{key}={n}"),
                n,
            })
        }
        Work::Own => Ok(Fitted::Own),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limit_takes_what_fills_it_but_never_more_than_the_scene_asks() {
        // 1/8 s per sample, 1 s fixed: 10 s fit 72 samples.
        let cost = CostModel::from_times(1, 1.125, 1.25);
        assert_eq!(units(&cost, 10.0, 1000), 72);
        assert_eq!(units(&cost, 10.0, 16), 16);
        assert_eq!(units(&cost, 0.001, 16), 1);
    }
}
