//! Radial density-estimation kernels for photon mapping: the `Kernel` interface, its
//! normalisation, kernel plugins, and the table of built-in kernels ([`KERNELS`]), one file
//! each in `kernel/` that ends with its factory. docs/extending.md adds a kernel.
//!
//! A kernel is a radial profile w(t), t = d / r in [0, 1]. The profile need not be normalised:
//! [`NormalizedKernel`] scales it so that it integrates to exactly one over the disc of radius
//! r (surface estimates) and over the ball of radius r (volume estimates). Normalising here,
//! not in each kernel, is what keeps any kernel (a plugin's included) from breaking energy
//! conservation.
//!
//! A kernel whose code foton does not own (a plugin's, [`Kernel::untrusted`]) is checked on
//! every use as well: a weight that is not finite and non-negative counts as zero, and the
//! first one is kept for [`NormalizedKernel::check_weights`], which the integrators call after
//! a render to fail with an error that names it (a check at 4097 points cannot see what the
//! code returns between them).

use crate::error::{Error, Result};
use std::f64::consts::PI;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// A radial kernel profile.
pub trait Kernel: Send + Sync {
    fn name(&self) -> &str;
    /// Unnormalised weight at t = d / r in [0, 1]; finite and non-negative.
    fn profile(&self, t: f64) -> f64;
    /// The kernel's own parameters as an integrator reads them (`cone_c`), for
    /// `Integrator::parameters`.
    fn parameters(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
    /// True for a profile from code foton does not own (a kernel plugin): each weight it
    /// gives is checked (module comment).
    fn untrusted(&self) -> bool {
        false
    }
}

crate::registry::builtins! {
    /// The built-in kernels, one line each (a file in `kernel/` that ends with its `FACTORY`):
    /// what `kernel = NAME` finds before the kernel plugins.
    pub const KERNELS: [dyn Kernel] = [
        box_kernel,
        cone_kernel,
        gaussian_kernel,
    ];
}
pub use box_kernel::BoxKernel;
pub use cone_kernel::ConeKernel;
pub use gaussian_kernel::GaussianKernel;

/// The names of [`KERNELS`], in its order.
pub const BUILTIN_KERNELS: &[&str] = &crate::registry::name_array::<_, { KERNELS.len() }>(KERNELS);

/// A kernel with its 2-D and 3-D normalisation constants.
pub struct NormalizedKernel {
    kernel: Box<dyn Kernel>,
    /// 1 / integral over the unit disc of w(|x|).
    norm2: f64,
    /// 1 / integral over the unit ball of w(|x|).
    norm3: f64,
    /// Whether each weight is checked (an untrusted profile).
    checked: bool,
    /// Set once a checked weight was bad; `first_bad` then holds its (t, w).
    bad: AtomicBool,
    first_bad: Mutex<Option<(f64, f64)>>,
}

/// Composite Simpson's rule of f on [0, 1].
fn simpson(f: impl Fn(f64) -> f64, n: usize) -> f64 {
    let h = 1.0 / n as f64;
    let mut s = f(0.0) + f(1.0);
    for i in 1..n {
        s += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

impl NormalizedKernel {
    /// Checks the profile on [0, 1] (finite, non-negative, not zero everywhere) and normalises
    /// it numerically in 2-D and 3-D.
    pub fn new(kernel: Box<dyn Kernel>) -> Result<Self> {
        const N: usize = 4096;
        for i in 0..=N {
            let t = i as f64 / N as f64;
            let w = kernel.profile(t);
            if !w.is_finite() || w < 0.0 {
                return Err(Error::Usage(format!(
                    "kernel `{}` is invalid: w({t}) = {w} (weights must be finite and >= 0 on [0, 1])",
                    kernel.name()
                )));
            }
        }
        let disc = 2.0 * PI * simpson(|t| kernel.profile(t) * t, N);
        let ball = 4.0 * PI * simpson(|t| kernel.profile(t) * t * t, N);
        if disc <= 0.0 || ball <= 0.0 {
            return Err(Error::Usage(format!(
                "kernel `{}` is zero everywhere on [0, 1]",
                kernel.name()
            )));
        }
        Ok(NormalizedKernel {
            checked: kernel.untrusted(),
            kernel,
            norm2: 1.0 / disc,
            norm3: 1.0 / ball,
            bad: AtomicBool::new(false),
            first_bad: Mutex::new(None),
        })
    }

    pub fn name(&self) -> &str {
        self.kernel.name()
    }

    /// `kernel = NAME` and the kernel's own parameters, as `Integrator::parameters` lists
    /// them.
    pub fn parameters(&self) -> Vec<crate::param::Parameter> {
        use crate::param::Parameter;
        let mut p = vec![Parameter::str("kernel", self.name())];
        for (key, value) in self.kernel.parameters() {
            p.push(Parameter::float(key, value as f32));
        }
        p
    }

    /// The profile at t, checked if untrusted: a bad weight is zero and is remembered.
    #[inline]
    fn profile(&self, t: f64) -> f64 {
        let w = self.kernel.profile(t);
        if self.checked && !(w >= 0.0 && w.is_finite()) {
            self.note_bad(t, w);
            return 0.0;
        }
        w
    }

    #[cold]
    fn note_bad(&self, t: f64, w: f64) {
        if !self.bad.swap(true, Ordering::Relaxed)
            && let Ok(mut first) = self.first_bad.lock()
        {
            *first = Some((t, w));
        }
    }

    /// An error naming the first bad weight an untrusted kernel gave since it was made (such
    /// weights were used as zero): a render that met one is wrong, and says so.
    pub fn check_weights(&self) -> Result<()> {
        if !self.bad.load(Ordering::Relaxed) {
            return Ok(());
        }
        let (t, w) = self
            .first_bad
            .lock()
            .ok()
            .and_then(|f| *f)
            .unwrap_or((f64::NAN, f64::NAN));
        Err(Error::Render(format!(
            "kernel `{}` returned w({t}) = {w} during the render (weights must be finite and >= 0 \
             on [0, 1]; the kernel was checked at 4097 points only, and passed there)",
            self.name()
        )))
    }

    /// Weight of a photon at distance d in a surface estimate of radius r (per unit area).
    #[inline]
    pub fn weight_2d(&self, d: f32, r: f32) -> f32 {
        let t = (d / r) as f64;
        if t > 1.0 {
            return 0.0;
        }
        (self.norm2 * self.profile(t) / (r as f64 * r as f64)) as f32
    }

    /// Weight of a photon at distance d in a volume estimate of radius r (per unit volume).
    #[inline]
    pub fn weight_3d(&self, d: f32, r: f32) -> f32 {
        let t = (d / r) as f64;
        if t > 1.0 {
            return 0.0;
        }
        (self.norm3 * self.profile(t) / (r as f64).powi(3)) as f32
    }
}

/// The built-in kernel `name`; `cone_c` parameterises the cone (read as the scene files'
/// single-precision `cone_c`). None for an unknown name or a `cone_c` below 1.
pub fn builtin(name: &str, cone_c: f64) -> Option<Box<dyn Kernel>> {
    use crate::value::{Node, Table, Value};
    let at = |value| Node {
        value,
        line: 0,
        column: 0,
    };
    let table = at(Value::Table(Table(vec![(
        "cone_c".into(),
        at(Value::Float(cone_c)),
    )])));
    let props = crate::props::Properties::new(std::path::Path::new(""), "", &table).ok()?;
    let factory = crate::registry::find(KERNELS, name)?;
    (factory.create)(&props, &mut Vec::new(), &mut crate::registry::NoResources).ok()
}

/// A loaded kernel plugin (C ABI, found by [`crate::plugin`]): here, below `props`, which
/// hands a plugin the host's kernel plugins, so that `props` need not import `plugin`.
#[derive(Clone, Debug)]
pub struct KernelPlugin {
    pub name: String,
    pub file: std::path::PathBuf,
    weight: unsafe extern "C" fn(f64) -> f64,
}

impl KernelPlugin {
    /// `weight` must come from a kernel declaration whose version was checked
    /// ([`crate::plugin`] loads them).
    pub(crate) fn new(
        name: String,
        file: std::path::PathBuf,
        weight: unsafe extern "C" fn(f64) -> f64,
    ) -> KernelPlugin {
        KernelPlugin { name, file, weight }
    }
}

impl Kernel for KernelPlugin {
    fn name(&self) -> &str {
        &self.name
    }
    fn profile(&self, t: f64) -> f64 {
        // SAFETY: the function comes from a declaration whose version was checked.
        unsafe { (self.weight)(t) }
    }
    /// C code: called only while it is checked, then read from its table.
    fn untrusted(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_and_cone_match_closed_forms() {
        let b = NormalizedKernel::new(Box::new(BoxKernel)).unwrap();
        let r = 0.5f32;
        assert!((b.weight_2d(0.1, r) as f64 - 1.0 / (PI * 0.25)).abs() < 1e-5);
        assert!((b.weight_3d(0.1, r) as f64 - 1.0 / (4.0 / 3.0 * PI * 0.125)).abs() < 1e-4);
        for c in [1.0, 1.5, 3.0] {
            let k = NormalizedKernel::new(Box::new(ConeKernel { c })).unwrap();
            let expect = 1.0 / ((1.0 - 2.0 / (3.0 * c)) * PI);
            assert!((k.weight_2d(0.0, 1.0) as f64 - expect).abs() < 1e-5 * expect);
        }
    }
}
