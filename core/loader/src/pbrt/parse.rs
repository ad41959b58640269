//! pbrt-v4's statements (its `parse` in parser.cpp) into a list of [`Directive`]s, each with
//! its positional arguments and its typed parameter list, and the place it was written.
//! `Include` and `Import` are read where they stand: the file's statements take the place of
//! the statement (pbrt-v4 imports a file's shapes and materials in parallel, which renders the
//! same). pbrt-v4 looks a relative file name up in the main scene file's folder, then takes it
//! as it is (from the working folder); the including file's folder is tried after the first.

use super::Loc;
use super::lexer::{Tok, Token, tokenize};
use foton_core::error::{Error, Result};
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// The type of a parameter, as declared (`"float fov"`); pbrt-v3's `point`, `vector`,
/// `color` and `normal3` read as pbrt-v4's `point3`, `vector3`, `rgb` and `normal`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Type {
    Integer,
    Float,
    Point2,
    Vector2,
    Point3,
    Vector3,
    Normal,
    Rgb,
    Blackbody,
    Spectrum,
    Bool,
    String,
    Texture,
}

const TYPES: &[(&str, Type)] = &[
    ("integer", Type::Integer),
    ("float", Type::Float),
    ("point2", Type::Point2),
    ("vector2", Type::Vector2),
    ("point3", Type::Point3),
    ("point", Type::Point3),
    ("vector3", Type::Vector3),
    ("vector", Type::Vector3),
    ("normal", Type::Normal),
    ("normal3", Type::Normal),
    ("rgb", Type::Rgb),
    ("color", Type::Rgb),
    ("blackbody", Type::Blackbody),
    ("spectrum", Type::Spectrum),
    ("bool", Type::Bool),
    ("string", Type::String),
    ("texture", Type::Texture),
];

impl Type {
    pub fn name(self) -> &'static str {
        TYPES
            .iter()
            .find(|(_, t)| *t == self)
            .map_or("?", |(n, _)| n)
    }

    /// How many numbers one value of the type is (0: not numbers).
    fn width(self) -> usize {
        match self {
            Type::Integer | Type::Float | Type::Blackbody => 1,
            Type::Point2 | Type::Vector2 => 2,
            Type::Point3 | Type::Vector3 | Type::Normal | Type::Rgb => 3,
            Type::Spectrum => 2,
            Type::Bool | Type::String | Type::Texture => 0,
        }
    }
}

/// A parameter's values: numbers, strings or booleans.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    Nums(Vec<f64>),
    Strs(Vec<String>),
    Bools(Vec<bool>),
}

/// One `"type name" value(s)` of a parameter list.
#[derive(Clone, Debug)]
pub struct Param {
    pub ty: Type,
    pub name: String,
    pub values: Values,
    pub loc: Loc,
}

impl Param {
    /// `"float fov"`, for messages.
    pub fn decl(&self) -> String {
        format!("\"{} {}\"", self.ty.name(), self.name)
    }
}

/// A positional argument of a directive.
#[derive(Clone, Debug, PartialEq)]
pub enum Arg {
    Str(String),
    Num(f64),
    Word(String),
}

/// One statement: `Shape "sphere" "float radius" 2`.
#[derive(Clone, Debug)]
pub struct Directive {
    pub name: String,
    pub loc: Loc,
    pub args: Vec<Arg>,
    pub params: Vec<Param>,
}

impl Directive {
    /// The first string argument (the type of a `Shape`, the name of a `NamedMaterial`).
    pub fn string(&self, i: usize) -> &str {
        match self.args.get(i) {
            Some(Arg::Str(s) | Arg::Word(s)) => s,
            _ => "",
        }
    }

    pub fn numbers(&self) -> Vec<f64> {
        self.args
            .iter()
            .filter_map(|a| match a {
                Arg::Num(x) => Some(*x),
                _ => None,
            })
            .collect()
    }

    /// `Shape "sphere"` (or `WorldBegin`), for messages.
    pub fn what(&self) -> String {
        match self.args.first() {
            Some(Arg::Str(s)) => format!("{} {s:?}", self.name),
            _ => self.name.clone(),
        }
    }
}

/// What a directive takes after its name.
enum Shape {
    Nothing,
    Numbers(usize),
    /// 16 numbers in brackets (pbrt-v4 requires them; pbrt-v3 files may omit them).
    Matrix,
    Strings(usize),
    /// One string, then an optional second one (`MediumInterface`).
    OneOrTwoStrings,
    Word,
    /// `n` strings, then a parameter list.
    WithParams(usize),
    /// `Include` and `Import`.
    File,
    /// `Option`: a name and one value, as pbrt-v4's parser reads it (`Option "seed" 3`), or a
    /// typed parameter (`Option "bool disablepixeljitter" true`).
    Option,
}

fn grammar(name: &str) -> Option<Shape> {
    Some(match name {
        "AttributeBegin" | "AttributeEnd" | "WorldBegin" | "ReverseOrientation" | "ObjectEnd"
        | "TransformBegin" | "TransformEnd" | "WorldEnd" | "Identity" => Shape::Nothing,
        "Translate" | "Scale" => Shape::Numbers(3),
        "Rotate" => Shape::Numbers(4),
        "LookAt" => Shape::Numbers(9),
        "TransformTimes" => Shape::Numbers(2),
        "Transform" | "ConcatTransform" => Shape::Matrix,
        "CoordinateSystem" | "CoordSysTransform" | "ColorSpace" | "NamedMaterial"
        | "ObjectBegin" | "ObjectInstance" => Shape::Strings(1),
        "MediumInterface" => Shape::OneOrTwoStrings,
        "ActiveTransform" => Shape::Word,
        "Shape" | "Material" | "LightSource" | "AreaLightSource" | "Camera" | "Film"
        | "Sampler" | "Integrator" | "PixelFilter" | "Accelerator" | "MakeNamedMaterial"
        | "MakeNamedMedium" | "Attribute" => Shape::WithParams(1),
        "Option" => Shape::Option,
        "Texture" => Shape::WithParams(3),
        "Include" | "Import" => Shape::File,
        _ => return None,
    })
}

const DIRECTIVES: &[&str] = &[
    "Accelerator",
    "ActiveTransform",
    "AreaLightSource",
    "Attribute",
    "AttributeBegin",
    "AttributeEnd",
    "Camera",
    "ColorSpace",
    "ConcatTransform",
    "CoordSysTransform",
    "CoordinateSystem",
    "Film",
    "Identity",
    "Import",
    "Include",
    "Integrator",
    "LightSource",
    "LookAt",
    "MakeNamedMaterial",
    "MakeNamedMedium",
    "Material",
    "MediumInterface",
    "NamedMaterial",
    "ObjectBegin",
    "ObjectEnd",
    "ObjectInstance",
    "Option",
    "PixelFilter",
    "ReverseOrientation",
    "Rotate",
    "Sampler",
    "Scale",
    "Shape",
    "Texture",
    "Transform",
    "TransformTimes",
    "Translate",
    "WorldBegin",
];

/// The statements of the scene file `path`, its `Include`d and `Import`ed files read in
/// their place; `included` gathers the files read besides `path`.
pub fn parse_file(path: &Path, included: &mut Vec<PathBuf>) -> Result<Vec<Directive>> {
    let scene_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut out = Vec::new();
    let mut stack = vec![path.to_path_buf()];
    read_into(path, &scene_dir, &mut stack, included, &mut out)?;
    Ok(out)
}

/// The statements of `text` (tests; `Include` is looked up from the working folder).
#[cfg(test)]
pub fn parse_text(name: &str, text: &str) -> Result<Vec<Directive>> {
    let file: Rc<Path> = Rc::from(Path::new(name));
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::from(name)];
    parse_tokens(
        tokenize(&file, text)?,
        Path::new(""),
        &mut stack,
        &mut Vec::new(),
        &mut out,
    )?;
    Ok(out)
}

fn read_into(
    path: &Path,
    scene_dir: &Path,
    stack: &mut Vec<PathBuf>,
    included: &mut Vec<PathBuf>,
    out: &mut Vec<Directive>,
) -> Result<()> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let text = if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"))
    {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut flate2::read::GzDecoder::new(&bytes[..]), &mut s)
            .map_err(|e| Error::io(path, format!("cannot decompress: {e}")))?;
        s
    } else {
        String::from_utf8(bytes).map_err(|_| Error::io(path, "is not UTF-8 text"))?
    };
    let file: Rc<Path> = Rc::from(path);
    parse_tokens(tokenize(&file, &text)?, scene_dir, stack, included, out)
}

struct Cursor {
    tokens: Vec<Token>,
    next: usize,
    /// Where the file ends, for "expected ... at the end of the file".
    end: Loc,
}

impl Cursor {
    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.next)
    }

    fn take(&mut self, what: &str, after: &Loc) -> Result<Token> {
        let t = self.tokens.get(self.next).cloned().ok_or_else(|| {
            self.end.error(
                "syntax",
                format!(
                    "expected {what} (for the statement at line {}), found the end of the file",
                    after.line
                ),
            )
        })?;
        self.next += 1;
        Ok(t)
    }

    fn number(&mut self, what: &str, after: &Loc) -> Result<f64> {
        let t = self.take(what, after)?;
        match &t.tok {
            Tok::Word(w) => number(w).ok_or_else(|| {
                t.loc.error(
                    "syntax",
                    format!("expected {what}, found `{w}`: not a number"),
                )
            }),
            _ => Err(t
                .loc
                .error("syntax", format!("expected {what}, found {}", t.shown()))),
        }
    }

    fn string(&mut self, what: &str, after: &Loc) -> Result<String> {
        let t = self.take(what, after)?;
        match t.tok {
            Tok::Str(s) => Ok(s),
            _ => Err(t.loc.error(
                "syntax",
                format!("expected {what} (a quoted string), found {}", t.shown()),
            )),
        }
    }
}

/// A number as pbrt-v4 reads one (C's strtod: decimal, with an exponent; no `inf` or `nan`).
fn number(w: &str) -> Option<f64> {
    let ok = w
        .chars()
        .all(|c| c.is_ascii_digit() || matches!(c, '+' | '-' | '.' | 'e' | 'E'));
    if !ok {
        return None;
    }
    w.parse::<f64>().ok().filter(|x| x.is_finite())
}

fn parse_tokens(
    tokens: Vec<Token>,
    scene_dir: &Path,
    stack: &mut Vec<PathBuf>,
    included: &mut Vec<PathBuf>,
    out: &mut Vec<Directive>,
) -> Result<()> {
    let end = match tokens.last() {
        Some(t) => t.loc.clone(),
        None => return Ok(()),
    };
    let mut c = Cursor {
        tokens,
        next: 0,
        end,
    };
    while let Some(t) = c.tokens.get(c.next).cloned() {
        c.next += 1;
        let name = match &t.tok {
            Tok::Word(w) => w.clone(),
            _ => {
                return Err(t.loc.error(
                    "syntax",
                    format!(
                        "expected a directive (Shape, LookAt, WorldBegin...), found {}",
                        t.shown()
                    ),
                ));
            }
        };
        let Some(shape) = grammar(&name) else {
            return Err(t.loc.error(
                "syntax",
                format!(
                    "unknown directive `{name}`{}",
                    foton_core::error::suggestion(&name, DIRECTIVES.iter().copied())
                ),
            ));
        };
        let loc = t.loc.clone();
        let mut d = Directive {
            name,
            loc: loc.clone(),
            args: Vec::new(),
            params: Vec::new(),
        };
        match shape {
            Shape::Nothing => {}
            Shape::Numbers(n) => {
                for i in 0..n {
                    let x = c.number(&format!("number {} of {n} of {}", i + 1, d.name), &loc)?;
                    d.args.push(Arg::Num(x));
                }
            }
            Shape::Matrix => {
                let bracket = c.peek().is_some_and(|t| t.tok == Tok::Open);
                if bracket {
                    c.next += 1;
                }
                for i in 0..16 {
                    let x = c.number(&format!("number {} of 16 of {}", i + 1, d.name), &loc)?;
                    d.args.push(Arg::Num(x));
                }
                if bracket {
                    let t = c.take("`]` after the 16 numbers", &loc)?;
                    if t.tok != Tok::Close {
                        return Err(t.loc.error(
                            "syntax",
                            format!(
                                "expected `]` after the 16 numbers of {}, found {}",
                                d.name,
                                t.shown()
                            ),
                        ));
                    }
                }
            }
            Shape::Strings(n) => {
                for _ in 0..n {
                    let s = c.string(&format!("the name after {}", d.name), &loc)?;
                    d.args.push(Arg::Str(s));
                }
            }
            Shape::OneOrTwoStrings => {
                let s = c.string("a medium name after MediumInterface", &loc)?;
                d.args.push(Arg::Str(s));
                if let Some(Token {
                    tok: Tok::Str(s), ..
                }) = c.peek()
                {
                    d.args.push(Arg::Str(s.clone()));
                    c.next += 1;
                }
            }
            Shape::Word => {
                let t = c.take("StartTime, EndTime or All", &loc)?;
                match &t.tok {
                    Tok::Word(w) if matches!(w.as_str(), "StartTime" | "EndTime" | "All") => {
                        d.args.push(Arg::Word(w.clone()))
                    }
                    _ => {
                        return Err(t.loc.error(
                            "syntax",
                            format!(
                                "expected StartTime, EndTime or All after ActiveTransform, found {}",
                                t.shown()
                            ),
                        ));
                    }
                }
            }
            Shape::WithParams(n) => {
                for i in 0..n {
                    let what = match (d.name.as_str(), i) {
                        ("Texture", 0) => "the texture's name".to_string(),
                        ("Texture", 1) => {
                            "the texture's value type (\"spectrum\" or \"float\")".into()
                        }
                        ("Texture", _) => "the texture's class (\"imagemap\", \"scale\"...)".into(),
                        ("MakeNamedMaterial" | "MakeNamedMedium", _) => {
                            format!("the name after {}", d.name)
                        }
                        _ => format!("the type after {} (e.g. {} \"...\")", d.name, d.name),
                    };
                    let s = c.string(&what, &loc)?;
                    d.args.push(Arg::Str(s));
                }
                d.params = params(&mut c)?;
            }
            Shape::Option => {
                let typed = matches!(c.peek(), Some(Token { tok: Tok::Str(s), .. }) if s.split_whitespace().count() > 1);
                if typed {
                    d.params = params(&mut c)?;
                } else {
                    let name = c.string("the option's name after Option", &loc)?;
                    d.args.push(Arg::Str(name));
                    let t = c.take("the option's value", &loc)?;
                    d.args.push(match &t.tok {
                        Tok::Str(s) => Arg::Str(s.clone()),
                        Tok::Word(w) => Arg::Word(w.clone()),
                        _ => {
                            return Err(t.loc.error(
                                "syntax",
                                format!("expected the option's value, found {}", t.shown()),
                            ));
                        }
                    });
                }
            }
            Shape::File => {
                let name = c.string(&format!("the file name after {}", d.name), &loc)?;
                let path = resolve(scene_dir, &loc.file, &name);
                if !path.exists() {
                    return Err(loc.error(
                        &d.name,
                        format!(
                            "{name:?}: no such file (looked for in the main scene file's folder and the including file's)"
                        ),
                    ));
                }
                if stack.contains(&path) {
                    return Err(loc.error(
                        &d.name,
                        format!("{name:?} includes itself (through {})", shown_stack(stack)),
                    ));
                }
                included.push(path.clone());
                stack.push(path.clone());
                read_into(&path, scene_dir, stack, included, out)?;
                stack.pop();
                continue;
            }
        }
        out.push(d);
    }
    Ok(())
}

fn shown_stack(stack: &[PathBuf]) -> String {
    stack
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(" -> ")
}

/// A file named in a scene file: absolute as it is; else in the main scene file's folder
/// (pbrt-v4's `ResolveFilename`), else in the folder of the file that names it.
pub fn resolve(scene_dir: &Path, from: &Path, name: &str) -> PathBuf {
    let p = Path::new(name);
    if p.is_absolute() {
        return p.to_path_buf();
    }
    let main = scene_dir.join(p);
    if main.exists() {
        return main;
    }
    let own = from.parent().unwrap_or(Path::new("")).join(p);
    if own.exists() {
        return own;
    }
    main
}

/// A parameter list: `"type name" value` or `"type name" [ values ]`, until a token that is
/// not a quoted string.
fn params(c: &mut Cursor) -> Result<Vec<Param>> {
    let mut out = Vec::new();
    while let Some(Token {
        tok: Tok::Str(decl),
        loc,
    }) = c.peek().cloned()
    {
        c.next += 1;
        let mut words = decl.split_whitespace();
        let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
            return Err(loc.error(
                "syntax",
                format!(
                    "expected a parameter declaration \"type name\" (e.g. \"float radius\"), found {decl:?}"
                ),
            ));
        };
        let Some(&(_, ty)) = TYPES.iter().find(|(n, _)| *n == ty) else {
            return Err(loc.error(
                "syntax",
                format!(
                    "{decl:?}: unknown parameter type `{ty}`{}; expected one of: integer, float, point2, vector2, point3, vector3, normal, rgb, blackbody, spectrum, bool, string, texture",
                    foton_core::error::suggestion(ty, TYPES.iter().map(|(n, _)| *n))
                ),
            ));
        };
        let mut raw = Vec::new();
        let first = c.take(&format!("a value for {decl:?}"), &loc)?;
        if first.tok == Tok::Open {
            loop {
                let t = c.take(&format!("`]` closing the values of {decl:?}"), &loc)?;
                match t.tok {
                    Tok::Close => break,
                    Tok::Open => {
                        return Err(t.loc.error(
                            "syntax",
                            format!("`[` inside the values of {decl:?}: expected `]` first"),
                        ));
                    }
                    _ => raw.push(t),
                }
            }
        } else if first.tok == Tok::Close {
            return Err(first.loc.error(
                "syntax",
                format!("expected a value for {decl:?}, found `]`"),
            ));
        } else {
            raw.push(first);
        }
        let values = values(ty, &decl, &raw, &loc)?;
        out.push(Param {
            ty,
            name: name.to_string(),
            values,
            loc,
        });
    }
    Ok(out)
}

fn values(ty: Type, decl: &str, raw: &[Token], loc: &Loc) -> Result<Values> {
    let values = match ty {
        Type::String | Type::Texture => Values::Strs(
            raw.iter()
                .map(|t| match &t.tok {
                    Tok::Str(s) => Ok(s.clone()),
                    _ => Err(t.loc.error(
                        "syntax",
                        format!("{decl:?}: expected a quoted string, found {}", t.shown()),
                    )),
                })
                .collect::<Result<_>>()?,
        ),
        Type::Bool => Values::Bools(
            raw.iter()
                .map(|t| match &t.tok {
                    Tok::Str(s) | Tok::Word(s) if s == "true" => Ok(true),
                    Tok::Str(s) | Tok::Word(s) if s == "false" => Ok(false),
                    _ => Err(t.loc.error(
                        "syntax",
                        format!("{decl:?}: expected true or false, found {}", t.shown()),
                    )),
                })
                .collect::<Result<_>>()?,
        ),
        // A spectrum is numbers (wavelength-value pairs) or one string (a named spectrum or
        // a file).
        Type::Spectrum if raw.iter().all(|t| matches!(t.tok, Tok::Str(_))) => Values::Strs(
            raw.iter()
                .map(|t| match &t.tok {
                    Tok::Str(s) => s.clone(),
                    _ => unreachable!(),
                })
                .collect(),
        ),
        _ => {
            let mut nums = Vec::with_capacity(raw.len());
            for t in raw {
                let x = match &t.tok {
                    Tok::Word(w) => number(w),
                    _ => None,
                };
                let Some(x) = x else {
                    return Err(t.loc.error(
                        "syntax",
                        format!("{decl:?}: expected a number, found {}", t.shown()),
                    ));
                };
                if ty == Type::Integer && x.fract() != 0.0 {
                    return Err(t.loc.error(
                        "syntax",
                        format!("{decl:?}: expected an integer, found {x}"),
                    ));
                }
                nums.push(x);
            }
            Values::Nums(nums)
        }
    };
    let count = match &values {
        Values::Nums(v) => v.len(),
        Values::Strs(v) => v.len(),
        Values::Bools(v) => v.len(),
    };
    let width = ty.width();
    if count == 0 {
        return Err(loc.error("syntax", format!("{decl:?}: no values")));
    }
    if let Values::Nums(_) = values
        && width > 1
        && count % width != 0
    {
        let what = if ty == Type::Spectrum {
            "wavelength-value pairs".to_string()
        } else {
            format!("groups of {width} numbers")
        };
        return Err(loc.error(
            "syntax",
            format!("{decl:?}: {count} numbers, expected {what}"),
        ));
    }
    if ty == Type::Spectrum
        && let Values::Strs(s) = &values
        && s.len() != 1
    {
        return Err(loc.error(
            "syntax",
            format!(
                "{decl:?}: expected one spectrum name or file, found {}",
                s.len()
            ),
        ));
    }
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse_text("t.pbrt", text).unwrap_err().to_string()
    }

    #[test]
    fn directives_and_typed_parameters() {
        let d = parse_text(
            "t.pbrt",
            "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 45\n\
             Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point3 P\" [0 0 0 1 0 0 0 1 0]\n\
             \"point2 uv\" [0 0 1 0 0 1] \"normal N\" [0 0 1 0 0 1 0 0 1]\n\
             LightSource \"point\" \"rgb I\" [1 2 3] \"bool flag\" true \"string name\" \"x\"\n\
             Material \"diffuse\" \"spectrum reflectance\" [400 0.5 700 0.5] \"texture t\" \"tex\"\n\
             AreaLightSource \"diffuse\" \"blackbody L\" 6500 \"spectrum k\" \"metal-Au-k\"\n\
             Transform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1]\nMediumInterface \"a\" \"\"\nWorldBegin",
        )
        .unwrap();
        let names: Vec<&str> = d.iter().map(|d| d.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "LookAt",
                "Camera",
                "Shape",
                "LightSource",
                "Material",
                "AreaLightSource",
                "Transform",
                "MediumInterface",
                "WorldBegin"
            ]
        );
        assert_eq!(d[0].numbers().len(), 9);
        assert_eq!(d[1].string(0), "perspective");
        assert_eq!(d[1].params[0].values, Values::Nums(vec![45.0]));
        assert_eq!(d[2].params.len(), 4);
        assert_eq!(d[2].params[3].ty, Type::Normal);
        assert_eq!(d[2].params[2].loc.line, 4);
        assert_eq!(d[3].params[1].values, Values::Bools(vec![true]));
        assert_eq!(d[4].params[1].ty, Type::Texture);
        assert_eq!(
            d[5].params[1].values,
            Values::Strs(vec!["metal-Au-k".into()])
        );
        assert_eq!(d[6].numbers().len(), 16);
        assert_eq!(d[7].args.len(), 2);
    }

    #[test]
    fn clear_errors_with_places() {
        let e = err("Shape \"sphere\" \"float radius\" [ 1 2");
        assert!(e.contains("expected `]` closing the values"), "{e}");
        let e = err("Shape \"sphere\"\n  \"float radius\" 1x");
        assert!(
            e.contains("t.pbrt:2:18") && e.contains("expected a number"),
            "{e}"
        );
        let e = err("Shape \"sphere\" \"flaot radius\" 1");
        assert!(e.contains("unknown parameter type `flaot`"), "{e}");
        assert!(e.contains("float"), "{e}");
        let e = err("Shap \"sphere\"");
        assert!(
            e.contains("t.pbrt:1:1") && e.contains("unknown directive `Shap`"),
            "{e}"
        );
        assert!(e.contains("Shape"), "{e}");
        let e = err("Translate 1 2");
        assert!(e.contains("number 3 of 3 of Translate"), "{e}");
        let e = err("Shape \"trianglemesh\" \"point3 P\" [0 0 0 1]");
        assert!(e.contains("4 numbers, expected groups of 3"), "{e}");
        let e = err("Shape \"x\" \"integer indices\" [0 1.5 2]");
        assert!(e.contains("expected an integer"), "{e}");
        let e = err("Shape \"x\" \"radius\" 1");
        assert!(e.contains("expected a parameter declaration"), "{e}");
        let e = err("Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5");
        assert!(e.contains("end of the file"), "{e}");
        let e = err("Shape \"sphere\" \"bool x\" 1");
        assert!(e.contains("expected true or false"), "{e}");
        let e = err("[ 1 ]");
        assert!(e.contains("expected a directive"), "{e}");
        let e = err("Include \"does-not-exist.pbrt\"");
        assert!(e.contains("no such file"), "{e}");
    }

    #[test]
    fn include_reads_the_file_in_place() {
        let dir = std::env::temp_dir().join(format!("foton-pbrt-include-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        std::fs::write(dir.join("sub/geometry.pbrt"), "Shape \"sphere\"\n").unwrap();
        std::fs::write(
            dir.join("main.pbrt"),
            "WorldBegin\nInclude \"sub/geometry.pbrt\"\nAttributeBegin\nAttributeEnd\n",
        )
        .unwrap();
        std::fs::write(dir.join("loop.pbrt"), "Include \"loop.pbrt\"\n").unwrap();
        let mut included = Vec::new();
        let d = parse_file(&dir.join("main.pbrt"), &mut included).unwrap();
        let names: Vec<&str> = d.iter().map(|d| d.name.as_str()).collect();
        assert_eq!(
            names,
            ["WorldBegin", "Shape", "AttributeBegin", "AttributeEnd"]
        );
        assert!(d[1].loc.file.ends_with("sub/geometry.pbrt"));
        assert_eq!(included.len(), 1);
        let e = parse_file(&dir.join("loop.pbrt"), &mut Vec::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("includes itself"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
