//! A directive's parameter list as its plugin reads it (pbrt-v4's `ParameterDictionary`):
//! each parameter taken by name with its default written once; what nobody takes is left for
//! the reader to refuse or leave out (`Reader::finish`).

use super::Loc;
use super::parse::{Directive, Param, Type, Values};
use foton_core::error::Result;

pub struct Bag {
    /// `Shape "sphere"`, for messages.
    pub what: String,
    pub loc: Loc,
    params: Vec<Option<Param>>,
    /// `Attribute` defaults, the latest first (pbrt-v4 looks them up after the directive's
    /// own parameters, and never reports one unused).
    defaults: Vec<Option<Param>>,
}

impl Bag {
    pub fn new(d: &Directive) -> Bag {
        Bag {
            what: d.what(),
            loc: d.loc.clone(),
            params: d.params.iter().cloned().map(Some).collect(),
            defaults: Vec::new(),
        }
    }

    /// The bag with `Attribute` defaults (in the order written) behind its own parameters.
    pub fn with_defaults(mut self, defaults: &[Param]) -> Bag {
        self.defaults = defaults.iter().rev().cloned().map(Some).collect();
        self
    }

    /// The first parameter called `name` (pbrt-v4's lookups take the first), taken.
    pub fn take(&mut self, name: &str) -> Option<Param> {
        let own = self
            .params
            .iter_mut()
            .find(|p| p.as_ref().is_some_and(|p| p.name == name))
            .and_then(Option::take);
        own.or_else(|| {
            self.defaults
                .iter_mut()
                .find(|p| p.as_ref().is_some_and(|p| p.name == name))
                .and_then(Option::take)
        })
    }

    pub fn has(&self, name: &str) -> bool {
        self.params
            .iter()
            .chain(&self.defaults)
            .flatten()
            .any(|p| p.name == name)
    }

    /// Puts a parameter (back) among the bag's own, in front of the defaults.
    pub fn put(&mut self, p: Param) {
        self.params.push(Some(p));
    }

    /// The parameters nobody took.
    pub fn rest(&mut self) -> Vec<Param> {
        self.params.iter_mut().filter_map(Option::take).collect()
    }

    /// Numbers of one of the types `types` (None: not given).
    pub fn numbers(&mut self, name: &str, types: &[Type]) -> Result<Option<(Vec<f64>, Loc)>> {
        let Some(p) = self.take(name) else {
            return Ok(None);
        };
        match (&p.values, types.contains(&p.ty)) {
            (Values::Nums(v), true) => Ok(Some((v.clone(), p.loc))),
            _ => Err(p.loc.error(
                &self.what,
                format!(
                    "{}: expected {}",
                    p.decl(),
                    types
                        .iter()
                        .map(|t| format!("\"{} {name}\"", t.name()))
                        .collect::<Vec<_>>()
                        .join(" or ")
                ),
            )),
        }
    }

    fn one(&mut self, name: &str, types: &[Type]) -> Result<Option<(f64, Loc)>> {
        match self.numbers(name, types)? {
            None => Ok(None),
            Some((v, loc)) if v.len() == 1 => Ok(Some((v[0], loc))),
            Some((v, loc)) => Err(loc.error(
                &self.what,
                format!("\"{name}\": expected one value, found {}", v.len()),
            )),
        }
    }

    pub fn float_opt(&mut self, name: &str) -> Result<Option<(f64, Loc)>> {
        self.one(name, &[Type::Float])
    }

    pub fn float(&mut self, name: &str, default: f64) -> Result<f64> {
        Ok(self.float_opt(name)?.map_or(default, |(x, _)| x))
    }

    pub fn int_opt(&mut self, name: &str) -> Result<Option<(i64, Loc)>> {
        Ok(self
            .one(name, &[Type::Integer])?
            .map(|(x, loc)| (x as i64, loc)))
    }

    pub fn int(&mut self, name: &str, default: i64) -> Result<i64> {
        Ok(self.int_opt(name)?.map_or(default, |(x, _)| x))
    }

    pub fn bool(&mut self, name: &str, default: bool) -> Result<bool> {
        let Some(p) = self.take(name) else {
            return Ok(default);
        };
        match &p.values {
            Values::Bools(b) if p.ty == Type::Bool && b.len() == 1 => Ok(b[0]),
            _ => Err(p.loc.error(
                &self.what,
                format!("{}: expected one \"bool {name}\"", p.decl()),
            )),
        }
    }

    pub fn string_opt(&mut self, name: &str) -> Result<Option<(String, Loc)>> {
        let Some(p) = self.take(name) else {
            return Ok(None);
        };
        match &p.values {
            Values::Strs(s) if p.ty == Type::String && s.len() == 1 => {
                Ok(Some((s[0].clone(), p.loc)))
            }
            _ => Err(p.loc.error(
                &self.what,
                format!("{}: expected one \"string {name}\"", p.decl()),
            )),
        }
    }
}
