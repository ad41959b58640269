//! The surface of `foton_core::api`: what a plugin built against it may use, as one canonical
//! text, and the plugin API version computed from it. Shared by build.rs (which computes the
//! version) and the tests (which check what changes it and what does not).
//!
//! The surface is, for each item `src/api.rs` re-exports (following re-exports to the
//! definition): a struct's attributes, generics and public fields (and whether it has private
//! ones, which decide whether a plugin can build it); an enum's variants; a trait's items
//! without default bodies; a function's signature; a constant's or a type alias's definition;
//! a macro's whole text; an external item's path. For each exposed type, the signatures of
//! its public inherent methods and constants and the headers of the traits it implements;
//! and, since a plugin reaches them through those signatures and fields, the same again for
//! every type of the crate that they name, to the end of that chain. Items written inside a
//! macro invocation (a registration list such as `lights! { pub enum Light { .. } }`) are
//! read as items, with the macro's text, which adds their methods. Members marked
//! `#[doc(hidden)]` are the host's and not part of it. Doc comments, other
//! comments, formatting, function bodies and everything the chain does not reach are not
//! part of it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use syn::visit::Visit;
use syn::visit_mut::VisitMut;
use syn::{Attribute, Item, UseTree, Visibility};

/// A module of the crate: its path from the crate root and its items.
struct Module {
    path: Vec<String>,
    items: Vec<Item>,
    /// The items written inside a macro invocation (`lights! { pub enum Light { .. } }`),
    /// which are among `items`, with the name of the macro that expands them.
    expanded_by: BTreeMap<String, String>,
}

/// Whether an attribute `#[name(args)]` is among `attrs` (`cfg(test)`, `doc(hidden)`).
fn has_attr(attrs: &[Attribute], name: &str, args: &str) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident(name)
            && a.meta
                .require_list()
                .is_ok_and(|l| l.tokens.to_string().trim() == args)
    })
}

fn collect_modules(path: Vec<String>, mut items: Vec<Item>, out: &mut Vec<Module>) {
    // A registration macro's input that is itself items (an enum the macro emits with its
    // dispatch) is read as items; the macro's text goes on the surface with them (see
    // `surface`), since its expansion adds their methods.
    let mut expanded_by = BTreeMap::new();
    let invocations: Vec<syn::ItemMacro> = items
        .iter()
        .filter_map(|i| match i {
            Item::Macro(m) if m.ident.is_none() => Some(m.clone()),
            _ => None,
        })
        .collect();
    for m in invocations {
        let Ok(file) = syn::parse2::<syn::File>(m.mac.tokens.clone()) else {
            continue;
        };
        let Some(macro_name) = m.mac.path.segments.last().map(|s| s.ident.to_string()) else {
            continue;
        };
        for inner in file.items {
            if let Some(name) = item_name(&inner) {
                expanded_by.insert(name, macro_name.clone());
                items.push(inner);
            }
        }
    }
    for item in &items {
        if let Item::Mod(m) = item
            && let Some((_, inner)) = &m.content
            && !has_attr(&m.attrs, "cfg", "test")
        {
            let mut p = path.clone();
            p.push(m.ident.to_string());
            collect_modules(p, inner.clone(), out);
        }
    }
    out.push(Module {
        path,
        items,
        expanded_by,
    });
}

fn read_modules(dir: &Path, prefix: &[String], out: &mut Vec<Module>) -> Result<(), String> {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .map(|e| e.map(|e| e.path()).map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    entries.sort();
    for path in entries {
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            let mut p = prefix.to_vec();
            p.push(stem);
            read_modules(&path, &p, out)?;
        } else if path.extension().is_some_and(|e| e == "rs") {
            let text =
                std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            let file = syn::parse_file(&text).map_err(|e| format!("{}: {e}", path.display()))?;
            let mut p = prefix.to_vec();
            if stem != "mod" && !(prefix.is_empty() && stem == "lib") {
                p.push(stem);
            }
            collect_modules(p, file.items, out);
        }
    }
    Ok(())
}

/// Removes what is not interface: doc attributes and function bodies.
struct Strip;
impl VisitMut for Strip {
    fn visit_attributes_mut(&mut self, attrs: &mut Vec<Attribute>) {
        attrs.retain(|a| !a.path().is_ident("doc") && !a.path().is_ident("inline"));
    }
    fn visit_block_mut(&mut self, block: &mut syn::Block) {
        block.stmts.clear();
    }
    fn visit_trait_item_fn_mut(&mut self, f: &mut syn::TraitItemFn) {
        f.default = None;
        syn::visit_mut::visit_trait_item_fn_mut(self, f);
    }
}

fn tokens(mut item: Item) -> String {
    Strip.visit_item_mut(&mut item);
    canonical(&item)
}

/// The tokens as text, without trailing commas (which rustfmt adds or removes with the
/// length of a line). A one-element tuple `(T,)` reads as `(T)` here: no signature of the
/// surface uses one.
fn canonical(tokens: &impl quote::ToTokens) -> String {
    use proc_macro2::{Group, TokenStream, TokenTree};
    fn strip(stream: TokenStream) -> TokenStream {
        let mut out: Vec<TokenTree> = stream
            .into_iter()
            .map(|t| match t {
                TokenTree::Group(g) => {
                    TokenTree::Group(Group::new(g.delimiter(), strip(g.stream())))
                }
                other => other,
            })
            .collect();
        if matches!(out.last(), Some(TokenTree::Punct(p)) if p.as_char() == ',') {
            out.pop();
        }
        out.into_iter().collect()
    }
    strip(tokens.to_token_stream()).to_string()
}

fn is_pub(vis: &Visibility) -> bool {
    matches!(vis, Visibility::Public(_))
}

/// `#[doc(hidden)]`: public for the host's crates, not promised to plugins (the rule
/// cargo-semver-checks follows too).
fn is_hidden(attrs: &[Attribute]) -> bool {
    has_attr(attrs, "doc", "hidden")
}

/// The identifiers of the paths a piece of syntax names (types, traits), and the paths of
/// more than one segment whole (`point::PointLight`), for the chain.
#[derive(Default)]
struct Names(BTreeSet<String>, BTreeSet<Vec<String>>);
impl<'a> Visit<'a> for Names {
    fn visit_path(&mut self, p: &'a syn::Path) {
        for seg in &p.segments {
            self.0.insert(seg.ident.to_string());
        }
        if p.segments.len() > 1 {
            self.1
                .insert(p.segments.iter().map(|s| s.ident.to_string()).collect());
        }
        syn::visit::visit_path(self, p);
    }
}

/// Where an item is defined: module and name.
type Def = (Vec<String>, String);

struct Crate {
    modules: Vec<Module>,
}

impl Crate {
    fn module(&self, path: &[String]) -> Option<&Module> {
        self.modules.iter().find(|m| m.path == path)
    }

    /// The definition `module::name` stands for, following `pub use`; None for external items.
    fn resolve(&self, module: &[String], name: &str, depth: u32) -> Option<Def> {
        if depth > 16 {
            return None;
        }
        let m = self.module(module)?;
        for item in &m.items {
            if item_name(item).as_deref() == Some(name) {
                return Some((module.to_vec(), name.to_string()));
            }
        }
        for item in &m.items {
            if let Item::Use(u) = item {
                for (alias, path) in use_leaves(&u.tree, Vec::new()) {
                    if alias == name {
                        return self.resolve_path(module, &path, depth + 1);
                    }
                }
            }
        }
        for item in &m.items {
            if let Item::Use(u) = item {
                for prefix in use_globs(&u.tree, Vec::new()) {
                    let mut path = prefix;
                    path.push(name.to_string());
                    if let Some(def) = self.resolve_path(module, &path, depth + 1) {
                        return Some(def);
                    }
                }
            }
        }
        // A #[macro_export] macro lives at the crate root.
        if module.is_empty() {
            for m in &self.modules {
                for item in &m.items {
                    if let Item::Macro(mac) = item
                        && mac.ident.as_ref().is_some_and(|i| i == name)
                    {
                        return Some((m.path.clone(), name.to_string()));
                    }
                }
            }
        }
        None
    }

    fn resolve_path(&self, from: &[String], path: &[String], depth: u32) -> Option<Def> {
        let (first, rest) = path.split_first()?;
        let mut module: Vec<String> = match first.as_str() {
            "crate" => Vec::new(),
            "self" => from.to_vec(),
            "super" => from[..from.len().saturating_sub(1)].to_vec(),
            _ if self
                .module(&[from, std::slice::from_ref(first)].concat())
                .is_some() =>
            {
                [from, std::slice::from_ref(first)].concat()
            }
            _ => return None,
        };
        let (name, mods) = rest.split_last()?;
        module.extend(mods.iter().cloned());
        self.resolve(&module, name, depth)
    }

    fn item(&self, def: &Def) -> Option<&Item> {
        self.module(&def.0)?
            .items
            .iter()
            .find(|i| item_name(i).as_deref() == Some(def.1.as_str()))
    }

    /// Which definition the type name `name` used in module `module` stands for.
    fn resolve_in(&self, module: &[String], name: &str) -> Option<Def> {
        self.resolve(module, name, 0)
    }
}

fn item_name(item: &Item) -> Option<String> {
    Some(match item {
        Item::Struct(i) => i.ident.to_string(),
        Item::Enum(i) => i.ident.to_string(),
        Item::Trait(i) => i.ident.to_string(),
        Item::Fn(i) => i.sig.ident.to_string(),
        Item::Const(i) => i.ident.to_string(),
        Item::Static(i) => i.ident.to_string(),
        Item::Type(i) => i.ident.to_string(),
        Item::Union(i) => i.ident.to_string(),
        Item::Macro(i) => i.ident.as_ref()?.to_string(),
        _ => return None,
    })
}

/// The leaves of a use tree: (name it is known by, full path).
fn use_leaves(tree: &UseTree, prefix: Vec<String>) -> Vec<(String, Vec<String>)> {
    match tree {
        UseTree::Path(p) => {
            let mut prefix = prefix;
            prefix.push(p.ident.to_string());
            use_leaves(&p.tree, prefix)
        }
        UseTree::Name(n) => {
            let mut path = prefix;
            let name = n.ident.to_string();
            if name == "self" {
                let last = path.last().cloned().unwrap_or_default();
                return vec![(last, path)];
            }
            path.push(name.clone());
            vec![(name, path)]
        }
        UseTree::Rename(r) => {
            let mut path = prefix;
            path.push(r.ident.to_string());
            vec![(r.rename.to_string(), path)]
        }
        UseTree::Group(g) => g
            .items
            .iter()
            .flat_map(|t| use_leaves(t, prefix.clone()))
            .collect(),
        UseTree::Glob(_) => Vec::new(),
    }
}

/// The module paths a use tree imports everything from (`use a::b::*`).
fn use_globs(tree: &UseTree, prefix: Vec<String>) -> Vec<Vec<String>> {
    match tree {
        UseTree::Path(p) => {
            let mut prefix = prefix;
            prefix.push(p.ident.to_string());
            use_globs(&p.tree, prefix)
        }
        UseTree::Group(g) => g
            .items
            .iter()
            .flat_map(|t| use_globs(t, prefix.clone()))
            .collect(),
        UseTree::Glob(_) => vec![prefix],
        _ => Vec::new(),
    }
}

/// The part of a definition that is interface, and the names it mentions.
fn definition(item: &Item) -> (String, Names) {
    let mut names = Names::default();
    let text = match item {
        Item::Struct(s) => {
            let mut s = s.clone();
            let promised = |f: &&syn::Field| is_pub(&f.vis) && !is_hidden(&f.attrs);
            let private = s.fields.iter().any(|f| !promised(&f));
            let kept: Vec<syn::Field> = s.fields.iter().filter(promised).cloned().collect();
            match &mut s.fields {
                syn::Fields::Named(f) => f.named = kept.into_iter().collect(),
                syn::Fields::Unnamed(f) => f.unnamed = kept.into_iter().collect(),
                syn::Fields::Unit => {}
            }
            names.visit_item_struct(&s);
            format!("{} private_fields={private}", tokens(Item::Struct(s)))
        }
        Item::Macro(m) => quote::ToTokens::to_token_stream(&m.mac).to_string(),
        other => {
            let mut stripped = other.clone();
            Strip.visit_item_mut(&mut stripped);
            if !matches!(other, Item::Fn(_) | Item::Const(_) | Item::Static(_)) {
                names.visit_item(&stripped);
            } else if let Item::Fn(f) = &stripped {
                names.visit_signature(&f.sig);
            } else if let Item::Const(c) = &stripped {
                names.visit_type(&c.ty);
            }
            tokens(stripped)
        }
    };
    (text, names)
}

/// The canonical text of the surface of `src/api.rs` in the crate whose sources are `src`.
pub fn surface(src: &Path) -> Result<String, String> {
    let mut modules = Vec::new();
    read_modules(src, &[], &mut modules)?;
    let krate = Crate { modules };
    let api_path = vec!["api".to_string()];
    let api = krate
        .module(&api_path)
        .ok_or("src/api.rs: no such module")?;

    // What api.rs re-exports.
    let mut lines: BTreeSet<String> = BTreeSet::new();
    let mut todo: Vec<Def> = Vec::new();
    for item in &api.items {
        match item {
            Item::Use(u) if is_pub(&u.vis) => {
                for (alias, path) in use_leaves(&u.tree, Vec::new()) {
                    match krate.resolve_path(&api_path, &path, 0) {
                        Some(def) => {
                            lines.insert(format!("pub {alias} = {}::{}", def.0.join("::"), def.1));
                            todo.push(def);
                        }
                        None if path[0] == "crate" => {
                            return Err(format!(
                                "src/api.rs: `{}` resolves to no item of the crate",
                                path.join("::")
                            ));
                        }
                        None => {
                            lines.insert(format!("pub {alias} = extern {}", path.join("::")));
                        }
                    }
                }
            }
            Item::Use(_) => {}
            other => {
                let (text, _) = definition(other);
                lines.insert(format!("api item {text}"));
            }
        }
    }

    // Each exposed definition, the members of exposed types, and the chain of named types.
    let mut seen: BTreeSet<Def> = BTreeSet::new();
    while let Some(def) = todo.pop() {
        if !seen.insert(def.clone()) {
            continue;
        }
        let Some(item) = krate.item(&def) else {
            continue;
        };
        let (text, names) = definition(item);
        // The names each part mentions, with the module they are written in.
        let mut mentioned: Vec<(Vec<String>, Names)> = vec![(def.0.clone(), names)];
        let key = format!("{}::{}", def.0.join("::"), def.1);
        lines.insert(format!("{key}: {text}"));
        if let Some(name) = krate.module(&def.0).and_then(|m| m.expanded_by.get(&def.1)) {
            let mac = krate.modules.iter().flat_map(|m| &m.items).find(
                |i| matches!(i, Item::Macro(m) if m.ident.as_ref().is_some_and(|i| i == name)),
            );
            if let Some(Item::Macro(mac)) = mac {
                let text = quote::ToTokens::to_token_stream(&mac.mac).to_string();
                lines.insert(format!("{key}: expanded by {name}: {text}"));
            }
        }
        if matches!(
            item,
            Item::Struct(_) | Item::Enum(_) | Item::Trait(_) | Item::Type(_) | Item::Union(_)
        ) {
            for m in &krate.modules {
                for it in &m.items {
                    let Item::Impl(imp) = it else { continue };
                    let syn::Type::Path(tp) = &*imp.self_ty else {
                        continue;
                    };
                    let Some(last) = tp.path.segments.last() else {
                        continue;
                    };
                    if last.ident != def.1 || krate.resolve_in(&m.path, &def.1) != Some(def.clone())
                    {
                        continue;
                    }
                    let mut header = imp.clone();
                    header.items.clear();
                    Strip.visit_item_impl_mut(&mut header);
                    let head = canonical(&header);
                    let mut names = Names::default();
                    if imp.trait_.is_some() {
                        // The chain goes on through the impl's generics, not into the trait:
                        // a trait api.rs does not name cannot be used by a plugin.
                        names.visit_generics(&header.generics);
                        mentioned.push((m.path.clone(), names));
                        lines.insert(format!("{key}: {head}"));
                        continue;
                    }
                    for member in &imp.items {
                        let text = match member {
                            syn::ImplItem::Fn(f) if is_pub(&f.vis) && !is_hidden(&f.attrs) => {
                                names.visit_signature(&f.sig);
                                let mut f = f.clone();
                                Strip.visit_impl_item_fn_mut(&mut f);
                                let f = syn::ImplItemFn {
                                    block: syn::parse_quote!({}),
                                    ..f
                                };
                                canonical(&f)
                            }
                            syn::ImplItem::Const(c) if is_pub(&c.vis) && !is_hidden(&c.attrs) => {
                                names.visit_type(&c.ty);
                                let mut c = c.clone();
                                Strip.visit_impl_item_const_mut(&mut c);
                                canonical(&c)
                            }
                            _ => continue,
                        };
                        lines.insert(format!("{key}: {head} {text}"));
                    }
                    mentioned.push((m.path.clone(), names));
                }
            }
        }
        let mut reached = Vec::new();
        for (module, names) in mentioned {
            for name in names.0 {
                reached.extend(krate.resolve_in(&module, &name));
            }
            for path in names.1 {
                reached.extend(krate.resolve_path(&module, &path, 0));
            }
        }
        for next in reached {
            if !seen.contains(&next)
                && krate.item(&next).is_some_and(|i| {
                    matches!(
                        i,
                        Item::Struct(_)
                            | Item::Enum(_)
                            | Item::Trait(_)
                            | Item::Type(_)
                            | Item::Union(_)
                    )
                })
            {
                todo.push(next);
            }
        }
    }
    Ok(lines.into_iter().collect::<Vec<_>>().join("\n"))
}

/// FNV-1a over the surface, folded to 32 bits: the plugin API version.
pub fn version(surface: &str) -> u32 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for b in surface.bytes() {
        h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    (h ^ (h >> 32)) as u32
}

/// Every definition the surface names, with how many lines it has there.
#[allow(dead_code)]
pub fn keys(surface: &str) -> BTreeMap<String, usize> {
    let mut keys = BTreeMap::new();
    for line in surface.lines() {
        if let Some((k, _)) = line.split_once(": ") {
            *keys.entry(k.to_string()).or_insert(0) += 1;
        }
    }
    keys
}
