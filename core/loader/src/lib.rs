//! foton-loader: scene files into foton-core's [`Scene`](foton_core::scene::Scene), outside the
//! plugin boundary.
//!
//! The readers are here rather than in core so that a fix to one of them leaves core, and so
//! the build identifier plugins are checked against, as it is: a plugin built before the fix
//! still loads. Core keeps the scene as plugins see it and builds it from the parts read here
//! ([`foton_core::scene::Scene::new`]).
//!
//! [`load`] is three steps. A format's reader ([`reader`]; chosen by the file's extension, [`formats`])
//! reads the file into core's `Document`, a tree of values each with its file and line:
//! TOML ([`document`]: TOML text into the `Document`, `--set`), Mitsuba XML ([`mitsuba`]:
//! Mitsuba 3 and 0.4 to 0.6) or pbrt-v4 ([`pbrt`]), each read as the TOML document it stands
//! for. `--set` overrides
//! change the document. The builder ([`from_document`]) turns any document into the `Scene`,
//! reading meshes ([`mesh`]: OBJ and [`ply`]) and images ([`texture`]: texture tables and
//! bitmaps; [`image`]: image files read and written).

mod build;
pub mod curve;
pub mod document;
pub mod formats;
pub mod image;
mod load;
pub mod mesh;
pub mod mitsuba;
#[cfg(test)]
mod mutations;
pub mod pbrt;
pub mod reader;
pub mod sdfgrid;
pub mod texture;

pub use build::from_document;
pub use document::TomlDocument;
pub use image::FilmFile;
pub use load::{load, load_with, set_relative_radius};
pub use mesh::ply;
