//! `cone`: Jensen's cone filter, with parameter `cone_c` (>= 1, default 1).

use super::Kernel;
use crate::registry::Factory;

/// Jensen's cone filter w = 1 - t / c, c >= 1.
pub struct ConeKernel {
    pub c: f64,
}

impl Kernel for ConeKernel {
    fn name(&self) -> &str {
        "cone"
    }
    fn profile(&self, t: f64) -> f64 {
        1.0 - t / self.c
    }
    fn parameters(&self) -> Vec<(&'static str, f64)> {
        vec![("cone_c", self.c)]
    }
}

pub const FACTORY: Factory<dyn Kernel> = Factory {
    name: "cone",
    description: "Jensen's cone filter 1 - t / cone_c",
    create: |p, _, _| {
        let c = p.f32("cone_c", 1.0)?;
        if c < 1.0 {
            return Err(p.error("cone_c", format!("must be >= 1, found {c}")));
        }
        Ok(Box::new(ConeKernel { c: c as f64 }))
    },
};
