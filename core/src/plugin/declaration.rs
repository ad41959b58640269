//! What an integrator plugin exports, and the guards compiled into it: the API versions, the
//! `#[repr(C)]` declarations (`FOTON_INTEGRATOR_PLUGIN`, the C kernel struct), the layout
//! fingerprint, `declare_integrator!` and the panic guards. This file and integrator.rs are the
//! plugin interface: a change to either is a new `PLUGIN_API_VERSION` (tests/tests/suite/plugin_api.rs
//! holds the rule).

use crate::error::{Error, Result};
use crate::film::Film;
use crate::integrator::{
    Budget, CreateIntegrator, Integrator, Parameter, PhotonMapView, RenderContext, Work,
};
use crate::props::Properties;
use crate::scene::Scene;
use std::ffi::{CStr, c_char};

/// Version of the plugin interface: a hash of the surface of [`crate::api`], computed by
/// build.rs (core/api_surface.rs), so that it changes exactly when what a plugin may use does.
pub const PLUGIN_API_VERSION: u32 = parse_u32(env!("FOTON_PLUGIN_API_VERSION"));

const fn parse_u32(decimal: &str) -> u32 {
    let bytes = decimal.as_bytes();
    let mut value = 0u32;
    let mut i = 0;
    while i < bytes.len() {
        value = value * 10 + (bytes[i] - b'0') as u32;
        i += 1;
    }
    value
}
/// Version of the C kernel interface.
pub const KERNEL_API_VERSION: u32 = 1;

pub const INTEGRATOR_SYMBOL: &[u8] = b"FOTON_INTEGRATOR_PLUGIN";
pub const KERNEL_SYMBOL: &[u8] = b"foton_kernel_plugin";

const fn c_str(bytes: &'static [u8]) -> &'static CStr {
    match CStr::from_bytes_with_nul(bytes) {
        Ok(c) => c,
        Err(_) => panic!("not a C string"),
    }
}
pub const CORE_VERSION_C: &CStr = c_str(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes());
pub const RUSTC_VERSION_C: &CStr = c_str(concat!(env!("FOTON_RUSTC_VERSION"), "\0").as_bytes());
pub const BUILD_ID_C: &CStr = c_str(concat!(env!("FOTON_BUILD_ID"), "\0").as_bytes());

/// Sizes and alignments of the types that cross the plugin boundary, folded into one number at
/// compile time. A plugin whose copy of core was built against other versions of glam or
/// obvhs (or other core types) gets another value, even when the sources hash the same.
pub const LAYOUT_FINGERPRINT: u64 = {
    use std::mem::{align_of, size_of};
    const fn mix(h: u64, x: usize) -> u64 {
        (h ^ x as u64).wrapping_mul(0x0100_0000_01b3)
    }
    let sizes = [
        size_of::<Scene>(),
        align_of::<Scene>(),
        size_of::<crate::accel::Accel>(),
        size_of::<obvhs::cwbvh::CwBvh>(),
        size_of::<obvhs::cwbvh::node::CwBvhNode>(),
        size_of::<obvhs::aabb::Aabb>(),
        size_of::<glam::Vec3>(),
        size_of::<glam::Vec3A>(),
        align_of::<glam::Vec3A>(),
        size_of::<glam::Mat4>(),
        size_of::<crate::geometry::Primitive>(),
        size_of::<crate::light::Light>(),
        size_of::<crate::material::Material>(),
        size_of::<crate::camera::Camera>(),
        size_of::<Film>(),
        size_of::<Properties<'static>>(),
        size_of::<RenderContext<'static>>(),
        size_of::<crate::kernel::KernelPlugin>(),
        size_of::<Error>(),
        size_of::<crate::value::Document>(),
    ];
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    let mut i = 0;
    while i < sizes.len() {
        h = mix(h, sizes[i]);
        i += 1;
    }
    h
};

/// What an integrator plugin exports. Only `api_version` may be read before it is checked.
#[repr(C)]
pub struct IntegratorDeclaration {
    pub api_version: u32,
    pub core_version: *const c_char,
    pub rustc_version: *const c_char,
    pub build_id: *const c_char,
    /// [`LAYOUT_FINGERPRINT`] as the plugin's copy of core computed it.
    pub layout: u64,
    pub name: *const c_char,
    pub description: *const c_char,
    /// Rust ABI: called only after every check passed.
    pub create: CreateIntegrator,
}

// SAFETY: the declaration is immutable static data; the pointers point to static C strings.
unsafe impl Sync for IntegratorDeclaration {}

/// What a kernel plugin exports (the C struct of plugins/foton_kernel.h).
#[repr(C)]
pub struct KernelDeclaration {
    pub api_version: u32,
    pub name: *const c_char,
    /// The radial profile w(t), t in [0, 1]; need not be normalised.
    /// Nullable on the C side; a null pointer is refused at load time.
    pub weight: Option<unsafe extern "C" fn(f64) -> f64>,
}

// SAFETY: as above.
unsafe impl Sync for KernelDeclaration {}

/// Declares the integrator plugin of a cdylib crate: `declare_integrator!("name",
/// "one-line description", create_fn)` with `create_fn(&Properties, &Scene) ->
/// Result<Box<dyn Integrator>>`. Put it once, at the end of the crate.
#[macro_export]
macro_rules! declare_integrator {
    ($name:literal, $description:literal, $create:path) => {
        fn __foton_create(
            props: &$crate::props::Properties<'_>,
            scene: &$crate::scene::Scene,
        ) -> $crate::Result<::std::boxed::Box<dyn $crate::integrator::Integrator>> {
            $crate::plugin::guarded_create(props, scene, $create)
        }

        #[unsafe(no_mangle)]
        pub static FOTON_INTEGRATOR_PLUGIN: $crate::plugin::IntegratorDeclaration =
            $crate::plugin::IntegratorDeclaration {
                api_version: $crate::plugin::PLUGIN_API_VERSION,
                core_version: $crate::plugin::CORE_VERSION_C.as_ptr(),
                rustc_version: $crate::plugin::RUSTC_VERSION_C.as_ptr(),
                build_id: $crate::plugin::BUILD_ID_C.as_ptr(),
                layout: $crate::plugin::LAYOUT_FINGERPRINT,
                name: concat!($name, "\0").as_ptr() as *const ::std::ffi::c_char,
                description: concat!($description, "\0").as_ptr() as *const ::std::ffi::c_char,
                create: __foton_create,
            };
    };
}

fn panic_message(payload: Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "panic with a non-string payload".into()
    }
}

/// Runs `f`, turning a panic into an error. Compiled into each plugin (whose copy of std
/// raised the panic), since a panic must not unwind across the library boundary.
pub fn catch<T>(what: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        Err(Error::Panic(format!(
            "panicked in {what}: {}",
            panic_message(payload)
        )))
    })
}

/// An integrator whose every entry point catches panics.
struct PanicGuard(Box<dyn Integrator>);

impl Integrator for PanicGuard {
    fn name(&self) -> &str {
        catch("name", || Ok(self.0.name())).unwrap_or("(panicked)")
    }
    fn parameters(&self) -> Vec<Parameter> {
        catch("parameters", || Ok(self.0.parameters())).unwrap_or_default()
    }
    fn render(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Film> {
        if scene.camera().meter().is_some() && !self.renders_meters() {
            return Err(Error::Usage(format!(
                "{}: the scene's sensor is a meter (a radiance or irradiance meter), which only paths traced from the camera reach; render it with `path`",
                self.name()
            )));
        }
        catch("render", || self.0.render(scene, ctx))
    }
    fn renders_meters(&self) -> bool {
        catch("renders_meters", || Ok(self.0.renders_meters())).unwrap_or(false)
    }
    fn budget(&self) -> Budget {
        catch("budget", || Ok(self.0.budget())).unwrap_or(Budget {
            work: Work::Own,
            scaled: Vec::new(),
        })
    }
    fn photon_maps(&self, scene: &Scene, ctx: &RenderContext<'_>) -> Result<Vec<PhotonMapView>> {
        catch("photon_maps", || self.0.photon_maps(scene, ctx))
    }
    fn bias(&self) -> Option<String> {
        catch("bias", || Ok(self.0.bias())).unwrap_or(None)
    }
    fn techniques(&self, depth: u32) -> Vec<String> {
        catch("techniques", || Ok(self.0.techniques(depth))).unwrap_or_default()
    }
    fn describe(&self) -> String {
        catch("describe", || Ok(self.0.describe())).unwrap_or_else(|e| e.to_string())
    }
}

/// Used by [`declare_integrator!`]: creates the integrator with panics caught, wrapped so that
/// its methods catch panics too.
pub fn guarded_create(
    props: &Properties<'_>,
    scene: &Scene,
    create: fn(&Properties<'_>, &Scene) -> Result<Box<dyn Integrator>>,
) -> Result<Box<dyn Integrator>> {
    let inner = catch("create", || create(props, scene))?;
    Ok(Box::new(PanicGuard(inner)))
}
