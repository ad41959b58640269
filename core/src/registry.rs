//! The tables of built-in plugins: one [`Factory`] per kind of thing a scene file names by
//! `type` (a medium) or by name (a density-estimation kernel), so that adding one is one file
//! plus one line (Mitsuba 3's `MI_EXPORT_PLUGIN`, pbrt-v4's `X::Create`).
//!
//! Each built-in lives in its own file, which ends with its factory: its name in scene files,
//! a one-line description, and `create`, which reads the plugin's parameters by name from its
//! [`Properties`] bag, with the defaults and the errors written there and nowhere else. The
//! kind's module lists its files in one `builtins!` invocation, one line each; that line
//! both declares the file's module and adds its factory to the kind's table. Everything that
//! lists or builds the kind (the loader, `foton check`, the docs' tests) reads the table.
//!
//! docs/extending.md walks through adding one of each.

use crate::Rgb;
use crate::error::{Error, Result, did_you_mean};
use crate::props::Properties;
use crate::texture::{Bitmap, Texture};
use glam::Mat4;

/// How a built-in plugin is made from its bag. Nested tables it reads (a medium's
/// `phase = { type = "hg", g = 0.8 }`) are pushed onto `nested`, so that the caller reports
/// their unknown keys like those of the bag itself; files, textures and transforms come from
/// `resources`, the scene reader's.
pub type Create<T> =
    for<'a> fn(&Properties<'a>, &mut Vec<Properties<'a>>, &mut dyn Resources) -> Result<Box<T>>;

/// What a built-in reads beyond its bag's numbers and strings, from the scene reader, which
/// knows the scene file's folder and its textures and collects its warnings.
pub trait Resources {
    /// The image named by the string parameter `key` (a path relative to the scene file's
    /// folder), in linear RGB (`raw`: the stored values, without decoding sRGB); the file
    /// becomes one of the scene's sources.
    fn bitmap(&mut self, bag: &Properties<'_>, key: &str, raw: bool) -> Result<Bitmap>;
    /// The transform table `key` (`matrix`, or translate, rotate and scale; the identity
    /// when absent).
    fn transform(&mut self, bag: &Properties<'_>, key: &str) -> Result<Mat4>;
    /// A colour parameter that may vary over the surface: `[r, g, b]` or a texture table;
    /// `default` when absent.
    fn texture(&mut self, bag: &Properties<'_>, key: &str, default: Rgb) -> Result<Texture>;
    /// A warning about parameter `key`, reported with the scene's others.
    fn warn(&mut self, bag: &Properties<'_>, key: &str, message: String);
    /// The bytes of the file named by the string parameter `key` (a path relative to the
    /// scene file's folder), which becomes one of the scene's sources.
    fn file(&mut self, bag: &Properties<'_>, key: &str) -> Result<Vec<u8>> {
        Err(bag.error(key, "files are read only in a scene file"))
    }
}

/// The resources of a bag read outside a scene file (an integrator's `kernel`, a test): no
/// files, so asking for an image, a transform or a texture table is an error; a colour given
/// as `[r, g, b]` (or absent) is the constant it says; warnings are dropped.
pub struct NoResources;

impl NoResources {
    fn none(bag: &Properties<'_>, key: &str) -> Error {
        bag.error(key, "files and textures are read only in a scene file")
    }
}

impl Resources for NoResources {
    fn bitmap(&mut self, bag: &Properties<'_>, key: &str, _: bool) -> Result<Bitmap> {
        Err(Self::none(bag, key))
    }
    fn transform(&mut self, bag: &Properties<'_>, key: &str) -> Result<Mat4> {
        Err(Self::none(bag, key))
    }
    fn texture(&mut self, bag: &Properties<'_>, key: &str, default: Rgb) -> Result<Texture> {
        if bag
            .node(key)
            .is_some_and(|n| matches!(n.value, crate::value::Value::Table(_)))
        {
            return Err(Self::none(bag, key));
        }
        Ok(Texture::Constant(bag.rgb(key, default)?))
    }
    fn warn(&mut self, _: &Properties<'_>, _: &str, _: String) {}
}

/// A built-in plugin of a kind `T` (`dyn Medium`, `dyn Kernel`): what its file registers.
pub struct Factory<T: ?Sized + 'static> {
    /// Its name in scene files (a medium's `type`, a photon integrator's `kernel`).
    pub name: &'static str,
    /// One line for listings.
    pub description: &'static str,
    pub create: Create<T>,
}

/// The factory named `name` in `table`.
pub fn find<'t, T: ?Sized>(table: &'t [Factory<T>], name: &str) -> Option<&'t Factory<T>> {
    table.iter().find(|f| f.name == name)
}

/// The names of a table, in its order.
pub fn names<T: ?Sized>(table: &[Factory<T>]) -> impl Iterator<Item = &'static str> + '_ {
    table.iter().map(|f| f.name)
}

/// The names of a table as an array, for a constant (`kernel::BUILTIN_KERNELS`).
pub const fn name_array<T: ?Sized, const N: usize>(table: &[Factory<T>]) -> [&'static str; N] {
    let mut out = [""; N];
    let mut i = 0;
    while i < N {
        out[i] = table[i].name;
        i += 1;
    }
    out
}

/// "unknown medium type "homogenous" (did you mean "homogeneous"?); expected one of:
/// homogeneous": the error for a name that `table` does not hold; `what` names the kind.
pub fn unknown<T: ?Sized>(what: &str, name: &str, table: &[Factory<T>]) -> String {
    let hint = match did_you_mean(name, names(table)) {
        Some(s) => format!(" (did you mean {s:?}?)"),
        None => String::new(),
    };
    format!(
        "unknown {what} {name:?}{hint}; expected one of: {}",
        names(table).collect::<Vec<_>>().join(", ")
    )
}

/// Declares the files of a kind's built-ins and its table of factories, one line per file:
///
/// ```text
/// crate::registry::builtins! {
///     /// The built-in media.
///     pub const MEDIA: [dyn Medium] = [
///         homogeneous,
///     ];
/// }
/// ```
///
/// declares `pub mod homogeneous;` (the file `medium/homogeneous.rs`, which defines
/// `pub const FACTORY: Factory<dyn Medium>`) and `pub const MEDIA` holding
/// `homogeneous::FACTORY`.
macro_rules! builtins {
    (
        $(#[$attr:meta])*
        $vis:vis const $table:ident: [$kind:ty] = [$($module:ident),* $(,)?];
    ) => {
        $(pub mod $module;)*
        $(#[$attr])*
        $vis const $table: &[$crate::registry::Factory<$kind>] = &[$($module::FACTORY),*];
    };
}
pub(crate) use builtins;

#[cfg(test)]
mod tests {
    //! What keeps "one file plus one line" true: every table entry is reachable by its name,
    //! the names are distinct, and what the docs list as built in is what the tables hold.

    use super::*;
    use crate::kernel::{BUILTIN_KERNELS, KERNELS, Kernel, NormalizedKernel};
    use crate::medium::{Homogeneous, MEDIA, Phase};
    use crate::value::{Node, Table, Value};
    use std::path::Path;

    fn distinct<T: ?Sized>(what: &str, table: &[Factory<T>]) {
        let mut seen: Vec<&str> = Vec::new();
        for f in table {
            assert!(!f.name.is_empty() && !f.description.is_empty(), "{what}");
            assert!(!seen.contains(&f.name), "{what}: `{}` twice", f.name);
            assert!(std::ptr::eq(find(table, f.name).unwrap(), f), "{what}");
            seen.push(f.name);
        }
    }

    #[test]
    fn every_table_holds_distinct_names() {
        distinct("media", MEDIA);
        distinct("lights", crate::light::LIGHTS);
        distinct("kernels", KERNELS);
        assert_eq!(names(KERNELS).collect::<Vec<_>>(), BUILTIN_KERNELS);
    }

    fn node(value: Value) -> Node {
        Node {
            value,
            line: 1,
            column: 1,
        }
    }

    fn bag(entries: &[(&str, Value)]) -> Node {
        let mut t = Table(Vec::new());
        for (k, v) in entries {
            t.insert(k, node(v.clone()));
        }
        node(Value::Table(t))
    }

    fn floats(v: [f64; 3]) -> Value {
        Value::Array(v.iter().map(|&x| node(Value::Float(x))).collect())
    }

    #[test]
    fn a_medium_from_the_table_equals_one_built_directly() {
        let phase = bag(&[("type", Value::Str("hg".into())), ("g", Value::Float(0.5))]);
        let table = bag(&[
            ("type", Value::Str("homogeneous".into())),
            ("sigma_a", floats([0.1, 0.2, 0.3])),
            ("sigma_s", floats([0.5, 0.25, 0.0])),
            ("phase", phase.value.clone()),
        ]);
        let props = Properties::new(Path::new("test.toml"), "media.fog", &table).unwrap();
        let mut nested = Vec::new();
        let m = (find(MEDIA, "homogeneous").unwrap().create)(&props, &mut nested, &mut NoResources)
            .unwrap();
        let direct = Homogeneous {
            sigma_a: crate::Rgb::new(0.1, 0.2, 0.3),
            sigma_s: crate::Rgb::new(0.5, 0.25, 0.0),
            phase: Phase::HenyeyGreenstein { g: 0.5 },
            emission: crate::Rgb::ZERO,
        };
        assert_eq!(m.homogeneous(), Some(direct));
        // The nested phase table is handed back, its keys read.
        assert_eq!(nested.len(), 1);
        assert!(nested[0].unused().is_empty());
        assert_eq!(
            props
                .unused()
                .iter()
                .map(|u| u.key.as_str())
                .collect::<Vec<_>>(),
            ["media.fog.type"],
            "the loader reads `type`; the factory reads everything else"
        );
    }

    #[test]
    fn a_kernel_from_the_table_equals_one_built_directly() {
        let table = bag(&[("cone_c", Value::Float(1.5))]);
        let props = Properties::new(Path::new("test.toml"), "integrators.photon", &table).unwrap();
        let k = (find(KERNELS, "cone").unwrap().create)(&props, &mut Vec::new(), &mut NoResources)
            .unwrap();
        let direct = crate::kernel::ConeKernel { c: 1.5 };
        assert_eq!(k.name(), direct.name());
        assert_eq!(k.parameters(), direct.parameters());
        let (a, b) = (
            NormalizedKernel::new(k).unwrap(),
            NormalizedKernel::new(Box::new(direct)).unwrap(),
        );
        for d in [0.0, 0.3, 0.9] {
            assert_eq!(a.weight_2d(d, 1.0), b.weight_2d(d, 1.0));
        }
    }

    /// Outside a scene file, a colour is a constant or its default; a texture table, an image
    /// or a transform is an error naming the parameter.
    #[test]
    fn no_resources_gives_constants_only() {
        use crate::Rgb;
        let table = bag(&[
            ("reflectance", floats([0.25, 0.5, 0.75])),
            (
                "pattern",
                bag(&[("type", Value::Str("checkerboard".into()))]).value,
            ),
            ("filename", Value::Str("sky.exr".into())),
        ]);
        let props = Properties::new(Path::new("t.toml"), "m", &table).unwrap();
        let mut none = NoResources;
        let constant = |t: Texture| match t {
            Texture::Constant(c) => c,
            other => panic!("{other:?}"),
        };
        let given = none.texture(&props, "reflectance", Rgb::ONE).unwrap();
        assert_eq!(constant(given), Rgb::new(0.25, 0.5, 0.75));
        let absent = none.texture(&props, "specular", Rgb::splat(0.5)).unwrap();
        assert_eq!(constant(absent), Rgb::splat(0.5));
        let e = none
            .texture(&props, "pattern", Rgb::ONE)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m.pattern") && e.contains("only in a scene file"),
            "{e}"
        );
        assert!(none.bitmap(&props, "filename", false).is_err());
        assert!(none.transform(&props, "to_world").is_err());
    }

    #[test]
    fn an_unknown_name_lists_the_table_and_suggests_the_nearest() {
        assert_eq!(
            unknown("medium type", "homogenous", MEDIA),
            "unknown medium type \"homogenous\" (did you mean \"homogeneous\"?); \
             expected one of: homogeneous, heterogeneous"
        );
    }

    /// docs/scene-format.md and docs/plugins.md name the built-in kernels in parentheses,
    /// "(`box`, `cone`, `gaussian`)" or "(`box`, `cone`, `gaussian`, in `core/...`)": exactly
    /// the table, neither more nor fewer.
    #[test]
    fn the_docs_list_the_built_in_kernels_of_the_table() {
        let listed = format!(
            "({}",
            names(KERNELS)
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        for doc in ["scene-format.md", "plugins.md"] {
            let path = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../docs")
                .join(doc);
            let text = std::fs::read_to_string(&path).unwrap();
            let complete = [")", ", in "]
                .iter()
                .any(|end| text.contains(&format!("{listed}{end}")));
            assert!(
                complete,
                "{} should list the built-in kernels as {listed})",
                path.display()
            );
        }
    }
}
