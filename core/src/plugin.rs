//! Plugins: integrators (Rust cdylibs) and density-estimation kernels (any language, C ABI).
//!
//! Rust has no stable ABI, so an integrator plugin exports one `#[repr(C)]` declaration,
//! `FOTON_INTEGRATOR_PLUGIN`, whose first field is the plugin API version and whose next fields
//! are C strings: the foton-core version, the rustc version and the build identifier of the
//! core it was compiled against. The host reads the version first, then the strings, and only
//! calls into the plugin when all of them equal its own. Panics are caught inside the plugin
//! (its std is its own copy) and returned as errors. Libraries are never unloaded.
//!
//! Kernel plugins export `foton_kernel_plugin` (see plugins/foton_kernel.h): a C struct with
//! the kernel API version, a name and w(t). They can be written in C or with any Rust compiler.
//!
//! Plugins are found only on the plugin search path, never from a path a scene names.

use crate::error::{Error, Result};
use crate::film::Film;
use crate::integrator::{
    Budget, CreateIntegrator, Integrator, Parameter, PhotonMapView, RenderContext, Work,
};
use crate::kernel::Kernel;
use crate::props::Properties;
use crate::scene::Scene;
use std::ffi::{CStr, c_char};
use std::path::{Path, PathBuf};

/// Version of the integrator plugin interface (bumped on any change of the declaration or of
/// the traits that cross the boundary).
pub const PLUGIN_API_VERSION: u32 = 2;
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
        size_of::<Registry>(),
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
        catch("render", || self.0.render(scene, ctx))
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

/// A loaded integrator plugin.
#[derive(Clone, Debug)]
pub struct IntegratorPlugin {
    pub name: String,
    pub description: String,
    pub file: PathBuf,
    create: CreateIntegrator,
}

impl IntegratorPlugin {
    /// Creates the integrator from its parameters. Unknown parameters are left for the caller
    /// to report (`props.unused()`).
    pub fn create(&self, props: &Properties<'_>, scene: &Scene) -> Result<Box<dyn Integrator>> {
        (self.create)(props, scene)
    }
}

/// A loaded kernel plugin.
#[derive(Clone, Debug)]
pub struct KernelPlugin {
    pub name: String,
    pub file: PathBuf,
    weight: unsafe extern "C" fn(f64) -> f64,
}

impl Kernel for KernelPlugin {
    fn name(&self) -> &str {
        &self.name
    }
    fn profile(&self, t: f64) -> f64 {
        // SAFETY: the function comes from a declaration whose version was checked.
        unsafe { (self.weight)(t) }
    }
}

/// A file on the search path that looked like a plugin but could not be used.
#[derive(Clone, Debug)]
pub struct Problem {
    pub file: PathBuf,
    pub message: String,
}

/// All plugins found on the search path.
#[derive(Clone, Debug, Default)]
pub struct Registry {
    pub integrators: Vec<IntegratorPlugin>,
    pub kernels: Vec<KernelPlugin>,
    pub problems: Vec<Problem>,
    pub searched: Vec<PathBuf>,
}

/// Whether a file name is a plugin candidate: `libfoton_*.so` on Linux (the platform's
/// dynamic-library prefix and suffix).
pub fn is_plugin_file(path: &Path) -> bool {
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return false;
    };
    let prefix = format!("{}foton_", std::env::consts::DLL_PREFIX);
    name.starts_with(&prefix) && name.ends_with(std::env::consts::DLL_SUFFIX)
}

/// The plugin search path, in order: `--plugin-dir` flags, `FOTON_PLUGIN_PATH`
/// (colon-separated), the folder of the running executable and its `plugins/` subfolder.
pub fn search_path(flag_dirs: &[PathBuf]) -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = flag_dirs.to_vec();
    if let Some(env) = std::env::var_os("FOTON_PLUGIN_PATH") {
        dirs.extend(std::env::split_paths(&env).filter(|p| !p.as_os_str().is_empty()));
    }
    if let Ok(exe) = std::env::current_exe()
        && let Some(dir) = exe.parent()
    {
        dirs.push(dir.to_path_buf());
        dirs.push(dir.join("plugins"));
    }
    dirs
}

fn read_c_str(ptr: *const c_char, what: &str, file: &Path) -> Result<String> {
    if ptr.is_null() {
        return Err(Error::Plugin {
            file: file.to_path_buf(),
            message: format!("its declaration has no {what}"),
        });
    }
    // SAFETY: a non-null pointer in a declaration whose API version matched points to a
    // NUL-terminated static string.
    Ok(unsafe { CStr::from_ptr(ptr) }
        .to_string_lossy()
        .into_owned())
}

enum Loaded {
    Integrator(IntegratorPlugin),
    Kernel(KernelPlugin),
}

/// Loads one plugin file and checks its declaration.
fn load(file: &Path) -> Result<Loaded> {
    let err = |message: String| Error::Plugin {
        file: file.to_path_buf(),
        message,
    };
    // SAFETY: loading runs the library's initialisers; only files on the user's plugin search
    // path are loaded, never one named by a scene.
    let lib = unsafe { libloading::Library::new(file) }.map_err(|e| {
        let why = std::error::Error::source(&e).map_or(String::new(), |s| format!(": {s}"));
        err(format!("cannot be loaded: {e}{why}"))
    })?;
    // Never unloaded: code and statics of the plugin may be referenced for the whole run.
    let lib: &'static libloading::Library = Box::leak(Box::new(lib));

    // SAFETY: the symbol is a static of the declared type (checked field by field below).
    if let Ok(sym) = unsafe { lib.get::<*const IntegratorDeclaration>(INTEGRATOR_SYMBOL) } {
        let decl: *const IntegratorDeclaration = *sym;
        // SAFETY: the first field is a u32 in every version of the declaration.
        let api = unsafe { std::ptr::read(decl as *const u32) };
        if api != PLUGIN_API_VERSION {
            return Err(err(format!(
                "plugin API version {api}, but this foton expects {PLUGIN_API_VERSION}; rebuild the plugin against this foton"
            )));
        }
        // SAFETY: the API version matched, so the layout is this version's.
        let decl = unsafe { &*decl };
        let checks = [
            ("foton-core version", decl.core_version, crate::CORE_VERSION),
            ("rustc version", decl.rustc_version, crate::RUSTC_VERSION),
            ("core build identifier", decl.build_id, crate::BUILD_ID),
        ];
        for (what, ptr, ours) in checks {
            let theirs = read_c_str(ptr, what, file)?;
            if theirs != ours {
                return Err(err(format!(
                    "built against {what} `{theirs}`, but this foton has `{ours}`; rebuild the plugin with the same rustc against the same foton-core"
                )));
            }
        }
        if decl.layout != LAYOUT_FINGERPRINT {
            return Err(err(format!(
                "its types have another layout (fingerprint {:016x}, this foton {LAYOUT_FINGERPRINT:016x}): it was built against other versions of foton-core's dependencies (glam, obvhs); rebuild it with this foton's Cargo.lock",
                decl.layout
            )));
        }
        return Ok(Loaded::Integrator(IntegratorPlugin {
            name: read_c_str(decl.name, "name", file)?,
            description: read_c_str(decl.description, "description", file)?,
            file: file.to_path_buf(),
            create: decl.create,
        }));
    }
    // SAFETY: as above, for the C kernel declaration.
    if let Ok(sym) = unsafe { lib.get::<*const KernelDeclaration>(KERNEL_SYMBOL) } {
        let decl: *const KernelDeclaration = *sym;
        // SAFETY: the first field is a u32 in every version.
        let api = unsafe { std::ptr::read(decl as *const u32) };
        if api != KERNEL_API_VERSION {
            return Err(err(format!(
                "kernel API version {api}, but this foton expects {KERNEL_API_VERSION}"
            )));
        }
        // SAFETY: version checked.
        let decl = unsafe { &*decl };
        return Ok(Loaded::Kernel(KernelPlugin {
            name: read_c_str(decl.name, "name", file)?,
            file: file.to_path_buf(),
            weight: decl
                .weight
                .ok_or_else(|| err("its declaration has no weight function".into()))?,
        }));
    }
    Err(err(format!(
        "not a foton plugin: it exports neither `{}` nor `{}`",
        String::from_utf8_lossy(INTEGRATOR_SYMBOL),
        String::from_utf8_lossy(KERNEL_SYMBOL)
    )))
}

impl Registry {
    /// Loads every plugin file in `dirs` (in order; a name found again later is shadowed).
    pub fn discover(dirs: &[PathBuf]) -> Registry {
        let mut reg = Registry {
            searched: dirs.to_vec(),
            ..Default::default()
        };
        for dir in dirs {
            let Ok(entries) = std::fs::read_dir(dir) else {
                continue;
            };
            let mut files: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && is_plugin_file(p))
                .collect();
            files.sort();
            for file in files {
                reg.add_file(&file);
            }
        }
        reg
    }

    /// Loads one file (given explicitly, e.g. in tests); problems are recorded, not returned.
    pub fn add_file(&mut self, file: &Path) {
        let canonical = file.canonicalize().unwrap_or_else(|_| file.to_path_buf());
        let seen = self
            .integrators
            .iter()
            .map(|p| &p.file)
            .chain(self.kernels.iter().map(|k| &k.file));
        if seen
            .into_iter()
            .any(|f| f.canonicalize().ok().as_ref() == Some(&canonical))
        {
            return;
        }
        match load(file) {
            Ok(Loaded::Integrator(p)) => {
                if !self.integrators.iter().any(|q| q.name == p.name) {
                    self.integrators.push(p);
                }
            }
            Ok(Loaded::Kernel(k)) => {
                if !self.kernels.iter().any(|q| q.name == k.name) {
                    self.kernels.push(k);
                }
            }
            Err(e) => self.problems.push(Problem {
                file: file.to_path_buf(),
                message: match e {
                    Error::Plugin { message, .. } => message,
                    other => other.to_string(),
                },
            }),
        }
    }

    /// The integrator plugin called `name`, or an error saying what was found and what failed.
    pub fn integrator(&self, name: &str) -> Result<&IntegratorPlugin> {
        if let Some(p) = self.integrators.iter().find(|p| p.name == name) {
            return Ok(p);
        }
        let mut msg = format!("no integrator plugin named `{name}` was found");
        if self.integrators.is_empty() {
            msg.push_str("; no integrator plugins were found at all");
        } else {
            let names: Vec<&str> = self.integrators.iter().map(|p| p.name.as_str()).collect();
            msg.push_str(&format!("; available: {}", names.join(", ")));
        }
        let dirs: Vec<String> = self
            .searched
            .iter()
            .map(|d| d.display().to_string())
            .collect();
        msg.push_str(&format!(
            "\n  searched (--plugin-dir, FOTON_PLUGIN_PATH, the executable's folder): {}",
            dirs.join(", ")
        ));
        for p in &self.problems {
            msg.push_str(&format!("\n  skipped {}: {}", p.file.display(), p.message));
        }
        Err(Error::Usage(msg))
    }

    /// The kernel plugin called `name`.
    pub fn kernel(&self, name: &str) -> Option<&KernelPlugin> {
        self.kernels.iter().find(|k| k.name == name)
    }
}
