//! `gaussian`: Jensen's Gaussian filter.

use super::Kernel;
use crate::registry::Factory;

/// Jensen's Gaussian filter with alpha = 0.918, beta = 1.953 (the normalisation that follows
/// replaces alpha, which on its own makes the filter integrate to about one half).
pub struct GaussianKernel;

impl Kernel for GaussianKernel {
    fn name(&self) -> &str {
        "gaussian"
    }
    fn profile(&self, t: f64) -> f64 {
        const ALPHA: f64 = 0.918;
        const BETA: f64 = 1.953;
        ALPHA * (1.0 - (1.0 - (-BETA * t * t / 2.0).exp()) / (1.0 - (-BETA).exp()))
    }
}

pub const FACTORY: Factory<dyn Kernel> = Factory {
    name: "gaussian",
    description: "Jensen's Gaussian filter (alpha = 0.918, beta = 1.953)",
    create: |_, _, _| Ok(Box::new(GaussianKernel)),
};
