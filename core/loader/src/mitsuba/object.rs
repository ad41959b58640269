//! An XML object element (`<bsdf type="...">`) and its properties, as the element-family
//! readers take them: each parameter read is taken out of the list, so that what is left at the
//! end was not read (Mitsuba's `Properties` and its check for unqueried ones).

use foton_core::error::{Error, Location, Result};
use glam::{DMat4, DVec3};
use std::path::PathBuf;

/// A property of an XML object.
#[derive(Clone, Debug)]
pub(super) enum Prop {
    Float(f64),
    Int(i64),
    Bool(bool),
    Str(String),
    Color(DVec3),
    Point(DVec3),
    Transform(DMat4),
    Ref(String),
    Object(Obj),
}

/// An XML object element (`<bsdf type="...">`): its properties by name, in order.
#[derive(Clone, Debug)]
pub(super) struct Obj {
    pub(super) tag: String,
    pub(super) ty: String,
    pub(super) id: Option<String>,
    pub(super) line: u32,
    /// The file it was written in (an `include`d one is not the scene's).
    pub(super) file: PathBuf,
    pub(super) props: Vec<(String, Prop, u32)>,
    /// Written in a file older than Mitsuba 2.0: read with 0.6's defaults where they differ.
    pub(super) v1: bool,
}

impl Obj {
    pub(super) fn place(&self) -> String {
        format!("{}:{}", self.file.display(), self.line)
    }

    pub(super) fn what(&self) -> String {
        format!("<{} type=\"{}\">", self.tag, self.ty)
    }

    pub(super) fn take(&mut self, name: &str) -> Option<(Prop, u32)> {
        let i = self.props.iter().position(|(n, _, _)| n == name)?;
        let (_, p, line) = self.props.remove(i);
        Some((p, line))
    }

    pub(super) fn error(&self, message: impl std::fmt::Display) -> Error {
        Error::Scene {
            location: Location {
                file: self.file.clone(),
                line: self.line,
                column: 1,
            },
            key: self.what(),
            message: message.to_string(),
        }
    }

    pub(super) fn float(&mut self, name: &str, default: f64) -> Result<f64> {
        match self.take(name) {
            None => Ok(default),
            Some((Prop::Float(x), _)) => Ok(x),
            Some((Prop::Int(i), _)) => Ok(i as f64),
            Some((p, _)) => {
                Err(self.error(format!("`{name}`: expected a number, found {}", show(&p))))
            }
        }
    }

    pub(super) fn int(&mut self, name: &str, default: i64) -> Result<i64> {
        match self.take(name) {
            None => Ok(default),
            Some((Prop::Int(i), _)) => Ok(i),
            Some((p, _)) => {
                Err(self.error(format!("`{name}`: expected an integer, found {}", show(&p))))
            }
        }
    }

    pub(super) fn boolean(&mut self, name: &str, default: bool) -> Result<bool> {
        match self.take(name) {
            None => Ok(default),
            Some((Prop::Bool(b), _)) => Ok(b),
            Some((p, _)) => {
                Err(self.error(format!("`{name}`: expected a boolean, found {}", show(&p))))
            }
        }
    }

    pub(super) fn string(&mut self, name: &str) -> Result<Option<String>> {
        match self.take(name) {
            None => Ok(None),
            Some((Prop::Str(s), _)) => Ok(Some(s)),
            Some((p, _)) => {
                Err(self.error(format!("`{name}`: expected a string, found {}", show(&p))))
            }
        }
    }

    /// A colour: `<rgb>`, a uniform `<spectrum>` or `<float>`.
    pub(super) fn color(&mut self, name: &str, default: DVec3) -> Result<DVec3> {
        match self.take(name) {
            None => Ok(default),
            Some((Prop::Color(c), _)) => Ok(c),
            Some((Prop::Float(x), _)) => Ok(DVec3::splat(x)),
            Some((Prop::Int(i), _)) => Ok(DVec3::splat(i as f64)),
            Some((Prop::Object(o), _)) if o.tag == "texture" => Err(self.error(format!(
                "`{name}`: textures ({}) are not supported yet",
                o.what()
            ))),
            Some((p, _)) => {
                Err(self.error(format!("`{name}`: expected a colour, found {}", show(&p))))
            }
        }
    }

    pub(super) fn point(&mut self, name: &str) -> Result<Option<DVec3>> {
        match self.take(name) {
            None => Ok(None),
            Some((Prop::Point(p), _)) => Ok(Some(p)),
            Some((p, _)) => {
                Err(self.error(format!("`{name}`: expected a point, found {}", show(&p))))
            }
        }
    }

    pub(super) fn transform(&mut self, name: &str) -> Result<DMat4> {
        match self.take(name) {
            None => Ok(DMat4::IDENTITY),
            Some((Prop::Transform(m), _)) => Ok(m),
            Some((p, _)) => Err(self.error(format!(
                "`{name}`: expected a transform, found {}",
                show(&p)
            ))),
        }
    }
}

/// A property's value as the file wrote it, for messages.
pub(super) fn show(p: &Prop) -> String {
    match p {
        Prop::Float(x) => x.to_string(),
        Prop::Int(i) => i.to_string(),
        Prop::Bool(b) => b.to_string(),
        Prop::Str(s) => format!("{s:?}"),
        Prop::Color(c) | Prop::Point(c) => format!("[{}, {}, {}]", c.x, c.y, c.z),
        Prop::Ref(id) => format!("<ref id={id:?}>"),
        Prop::Object(o) => o.what(),
        Prop::Transform(_) => "a transform".into(),
    }
}
