//! `box`: the constant kernel, 1 / (pi r^2) on the disc once normalised.

use super::Kernel;
use crate::registry::Factory;

/// w = 1.
pub struct BoxKernel;

impl Kernel for BoxKernel {
    fn name(&self) -> &str {
        "box"
    }
    fn profile(&self, _: f64) -> f64 {
        1.0
    }
}

pub const FACTORY: Factory<dyn Kernel> = Factory {
    name: "box",
    description: "constant weight over the disc or ball",
    create: |_, _, _| Ok(Box::new(BoxKernel)),
};
