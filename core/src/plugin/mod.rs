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

mod declaration;

pub use declaration::*;

use crate::error::{Error, Result};
use crate::integrator::{CreateIntegrator, Integrator};
pub use crate::kernel::KernelPlugin;
use crate::props::Properties;
use crate::scene::Scene;
use std::ffi::{CStr, c_char};
use std::path::{Path, PathBuf};

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
    // A plugin built again for a newer processor sits in a subfolder named by its level, and
    // is found first where the processor has that level (a name found later is shadowed).
    let variants: Vec<&str> = CPU_VARIANTS.into_iter().filter(|v| cpu_has(v)).collect();
    dirs.into_iter()
        .flat_map(|d| {
            let mut with = variants.iter().map(|v| d.join(v)).collect::<Vec<_>>();
            with.push(d);
            with
        })
        .collect()
}

/// The processor levels a plugin may also be built for (integrators/path/build.rs): the
/// level's name is its folder beside the baseline plugins and the tag on its build identifier.
pub const CPU_VARIANTS: [&str; 1] = ["x86-64-v3"];

/// Whether this processor has every feature of `variant` (one of [`CPU_VARIANTS`]).
pub fn cpu_has(variant: &str) -> bool {
    #[cfg(target_arch = "x86_64")]
    if variant == "x86-64-v3" {
        use std::arch::is_x86_feature_detected as has;
        // x86-64-v3 as rustc's target-cpu defines it (v2's features included).
        return has!("avx2")
            && has!("avx")
            && has!("bmi1")
            && has!("bmi2")
            && has!("f16c")
            && has!("fma")
            && has!("lzcnt")
            && has!("movbe")
            && has!("xsave")
            && has!("popcnt")
            && has!("sse4.2")
            && has!("ssse3")
            && has!("cmpxchg16b");
    }
    let _ = variant;
    false
}

/// Whether a plugin's core build identifier is acceptable to this host: its own, or its own
/// tagged with a processor level this processor has. Err says why not.
fn build_id_accepted(theirs: &str, ours: &str) -> std::result::Result<(), String> {
    if theirs == ours {
        return Ok(());
    }
    match theirs.strip_prefix(ours).and_then(|t| t.strip_prefix('+')) {
        Some(level) if cpu_has(level) => Ok(()),
        Some(level) => Err(format!(
            "built for the processor level {level}, which this processor does not have"
        )),
        None => Err(format!(
            "built against core build identifier `{theirs}`, but this foton has `{ours}`; rebuild the plugin with the same rustc against the same foton-core"
        )),
    }
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
        ];
        for (what, ptr, ours) in checks {
            let theirs = read_c_str(ptr, what, file)?;
            if theirs != ours {
                return Err(err(format!(
                    "built against {what} `{theirs}`, but this foton has `{ours}`; rebuild the plugin with the same rustc against the same foton-core"
                )));
            }
        }
        let theirs = read_c_str(decl.build_id, "core build identifier", file)?;
        build_id_accepted(&theirs, crate::BUILD_ID).map_err(err)?;
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
        return Ok(Loaded::Kernel(KernelPlugin::new(
            read_c_str(decl.name, "name", file)?,
            file.to_path_buf(),
            decl.weight
                .ok_or_else(|| err("its declaration has no weight function".into()))?,
        )));
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A plugin's build identifier is accepted when it is the host's, or the host's tagged
    /// with a processor level this processor has; never another build's, tagged or not.
    #[test]
    fn build_id_tagged_with_a_processor_level() {
        let ours = "0123456789abcdef-release";
        assert!(build_id_accepted(ours, ours).is_ok());
        let v3 = format!("{ours}+x86-64-v3");
        assert_eq!(build_id_accepted(&v3, ours).is_ok(), cpu_has("x86-64-v3"));
        let err = build_id_accepted(&format!("{ours}+x86-64-v9"), ours).unwrap_err();
        assert!(
            err.contains("x86-64-v9") && err.contains("does not have"),
            "{err}"
        );
        for other in [
            "fedcba9876543210-release",
            "fedcba9876543210-release+x86-64-v3",
            "0123456789abcdef-release-x86-64-v3",
        ] {
            let err = build_id_accepted(other, ours).unwrap_err();
            assert!(err.contains("rebuild the plugin"), "{err}");
        }
    }

    /// Each level's folder comes before the folder it is in, where the processor has it.
    #[test]
    fn variant_folders_are_searched_first() {
        let dirs = search_path(&[PathBuf::from("/p")]);
        let v3 = cpu_has("x86-64-v3");
        assert_eq!(
            dirs[0],
            PathBuf::from(if v3 { "/p/x86-64-v3" } else { "/p" })
        );
        assert_eq!(dirs.contains(&PathBuf::from("/p/x86-64-v3")), v3);
    }
}
