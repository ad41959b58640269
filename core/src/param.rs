//! A configured parameter of a plugin (an integrator's or a kernel's): its key and the value in
//! force, as `Integrator::parameters` lists them and the tools print them. Below both
//! `integrator` and `kernel`, which share it.

/// A parameter's value, as a scene file would write it.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    Int(i64),
    Float(f64),
    Bool(bool),
    Str(String),
}

impl std::fmt::Display for ParamValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamValue::Int(n) => write!(f, "{n}"),
            // A value that came from an f32 prints as that f32 (0.1, not 0.10000000149).
            ParamValue::Float(x) if (*x as f32) as f64 == *x => write!(f, "{}", *x as f32),
            ParamValue::Float(x) => write!(f, "{x}"),
            ParamValue::Bool(b) => write!(f, "{b}"),
            ParamValue::Str(s) => write!(f, "{s}"),
        }
    }
}

/// One configured parameter of an integrator: its key in `[integrators.NAME]` and the value
/// in force (the default where the scene gives none).
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    pub name: String,
    pub value: ParamValue,
}

impl Parameter {
    pub fn int(name: &str, value: impl TryInto<i64>) -> Parameter {
        let value = value.try_into().unwrap_or(i64::MAX);
        Parameter {
            name: name.into(),
            value: ParamValue::Int(value),
        }
    }
    pub fn float(name: &str, value: impl Into<f64>) -> Parameter {
        Parameter {
            name: name.into(),
            value: ParamValue::Float(value.into()),
        }
    }
    pub fn bool(name: &str, value: bool) -> Parameter {
        Parameter {
            name: name.into(),
            value: ParamValue::Bool(value),
        }
    }
    pub fn str(name: &str, value: impl Into<String>) -> Parameter {
        Parameter {
            name: name.into(),
            value: ParamValue::Str(value.into()),
        }
    }
}
