#!/usr/bin/env python3
"""Open rate of a folder of Mitsuba scene files with `foton check`.

Usage: open-rate.sh CORPUS FOTON [--timeout SECONDS] [--jobs N] [--tsv FILE]

Every .xml file under CORPUS whose root element is <scene> is checked twice, as written
(`foton check FILE`) and with `foton check --lenient FILE`, each under a timeout, from an empty
working folder (so that nothing resolves against the caller's folder by accident). The report
gives, per Mitsuba version (the root's `version` attribute, bucketed 0.x / 2.x / 3.x, "none"
when absent): the files, those whose assets are missing (counted apart and not judged), and
of the judged files those that opened as written, with --lenient, panicked, or timed out.
Then the failure histograms: the first `error:` line of each judged failure, normalised into a
category (locations, paths, numbers and long values removed), most frequent first, with one
example file each.

Assets are looked for as Mitsuba's file resolver would find them: relative to the scene's
folder, to the including file's folder, and to every <path value="..."/> folder, after
substituting <default> values. A file counts as "assets missing" when any mesh, texture,
volume, spectrum file or include it names (directly or through its includes) exists in none
of those places.

Python 3 standard library only.
"""

import argparse
import collections
import concurrent.futures
import os
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

HEAD_BYTES = 65536
PROLOGUE = re.compile(rb"^\s*(<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>]*>)", re.S)
ROOT = re.compile(rb"^\s*<([A-Za-z_][\w.-]*)")
VERSION = re.compile(rb"""\bversion\s*=\s*["']([^"']*)["']""")


def scene_root(path):
    """The `version` attribute of the root <scene> element ('' when absent), or None when
    the file's root element is not <scene>."""
    try:
        with open(path, "rb") as f:
            head = f.read(HEAD_BYTES)
    except OSError:
        return None
    if head.startswith(b"\xef\xbb\xbf"):
        head = head[3:]
    while True:
        m = PROLOGUE.match(head)
        if not m:
            break
        head = head[m.end():]
    m = ROOT.match(head)
    if not m or m.group(1) != b"scene":
        return None
    tag = head[m.start(): head.find(b">", m.end()) + 1]
    v = VERSION.search(tag)
    return v.group(1).decode("ascii", "replace") if v else ""


def bucket(version):
    if not version:
        return "none"
    major = version.split(".")[0].strip()
    if major == "0":
        return "0.x"
    if major in ("1", "2", "3"):
        return major + ".x"
    return "other"


def substitute(value, defaults):
    return re.sub(r"\$(\w+)", lambda m: defaults.get(m.group(1), m.group(0)), value)


def parse(path):
    """The file's element tree, as Mitsuba's parser (pugixml) reads it: a comment holding
    `--`, which Python's parser refuses, is still a comment there."""
    try:
        return ET.parse(path)
    except ET.ParseError:
        with open(path, "rb") as f:
            text = f.read()
        return ET.ElementTree(ET.fromstring(re.sub(rb"<!--.*?-->", b"", text, flags=re.S)))


def referenced_files(root):
    """(kind, value) pairs: every file a Mitsuba scene element names."""
    for el in root.iter():
        tag = el.tag if isinstance(el.tag, str) else ""
        if tag == "include" and el.get("filename"):
            yield "include", el.get("filename")
        elif tag == "string" and (el.get("name") or "").lower() == "filename" and el.get("value"):
            yield "file", el.get("value")
        elif tag in ("spectrum", "rgb", "texture", "shape") and el.get("filename"):
            yield "file", el.get("filename")


def resolve_folder(value, here, search):
    """A <path> folder as Mitsuba 3's parser finds it: relative to the XML file's folder
    first, else through the folders the resolver already has."""
    if os.path.isabs(value):
        return value
    first = os.path.join(here, value)
    if os.path.isdir(first):
        return first
    return next((os.path.join(d, value) for d in reversed(search) if os.path.isdir(os.path.join(d, value))), first)


def find_file(value, search):
    if os.path.isabs(value):
        return value if os.path.isfile(value) else None
    return next((os.path.join(d, value) for d in reversed(search) if os.path.isfile(os.path.join(d, value))), None)


def missing_assets(path, defaults=None, seen=None, search=None):
    """The files `path` (and its includes) name that exist nowhere Mitsuba would look."""
    seen = seen if seen is not None else set()
    if path in seen:
        return []
    seen.add(path)
    try:
        root = parse(path).getroot()
    except (ET.ParseError, OSError, ValueError):
        return []  # foton reports a malformed file itself; not an asset question
    defaults = dict(defaults or {})
    for el in root.iter("default"):
        name, value = el.get("name"), el.get("value")
        if name and value is not None:
            defaults.setdefault(name, value)
    here = os.path.dirname(os.path.abspath(path))
    search = search if search is not None else []  # shared: Mitsuba's resolver is global
    search.append(here)
    for el in root.iter("path"):
        value = el.get("value")
        if value:
            search.append(resolve_folder(substitute(value, defaults), here, search))
    missing = []
    for kind, value in referenced_files(root):
        value = substitute(value, defaults)
        if "$" in value:
            continue  # a default nobody set: the scene cannot name its file, foton says so
        found = find_file(value, search)
        if found is None:
            missing.append(value)
        elif kind == "include":
            missing += missing_assets(found, defaults, seen, search)
    return missing


def run_check(foton, scene, lenient, timeout, cwd):
    cmd = [foton, "check"] + (["--lenient"] if lenient else []) + [scene]
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", ""
    err = p.stderr.decode("utf-8", "replace")
    if p.returncode == 101 or "panicked at" in err:
        line = next((l for l in err.splitlines() if "panicked at" in l), "panic")
        following = err.split("panicked at", 1)[-1].splitlines()[1:2]
        return "panic", (line + " " + " ".join(following)).strip()
    if p.returncode == 0:
        return "ok", ""
    first = next((l for l in err.splitlines() if l.startswith("error:")), None)
    if first is None:
        lines = [l for l in err.splitlines() if l.strip()]
        first = lines[-1] if lines else f"exit code {p.returncode}, no message"
    return "error", first


LOCATION = re.compile(r"^(?:error:\s*)?(?:\S+?\.(?:xml|toml|obj|ply|serialized|exr|png|jpg|hdr)(?::\d+)*:\s*)+", re.I)
BACKQUOTED = re.compile(r"`([^`]*)`")
KEY_PATH = re.compile(r"[A-Za-z_][\w-]*(\[\d+\])?(\.[\w-]+(\[\d+\])?)+")
NUMBER = re.compile(r"[-+\d.eE]+")
FILE_NAME = re.compile(r"\.(obj|ply|serialized|exr|png|jpe?g|hdr|pfm|tga|bmp|xml|spd|vol|toml)$", re.I)
PATHLIKE = re.compile(r"(?:[\w.+-]*/)+[\w.+-]+")


def categorise(line):
    """The first error line with what varies from file to file taken out: the location, file
    paths, numbers and long values; short identifiers (element, plugin and parameter names)
    stay, because they say what was refused."""
    text = LOCATION.sub("", line.strip())

    def value(m):
        v = m.group(1)
        if v.startswith("<") and len(v) <= 80:
            return m.group(0)  # an element: `<bsdf type="ward">` says what refused
        if re.fullmatch(r"\s*[-+\d.eE]+\s*:\s*[-+\d.eE]+(\s*[,;]?\s*[-+\d.eE]+\s*:\s*[-+\d.eE]+)*\s*,?\s*", v):
            return "`<wavelength:value list>`"
        if re.fullmatch(r"\s*[-+\d.eE]+(\s*[,\s]\s*[-+\d.eE]+)+\s*", v):
            return "`<%d numbers>`" % len(NUMBER.findall(v))
        if FILE_NAME.search(v):
            return "`…`"
        if KEY_PATH.fullmatch(v):
            # A TOML key path: the names a scene gives its materials vary, the keys do not.
            v = re.sub(r"^(materials|media|textures|lights|shapes)\.[^.\[]+", r"\1.*", v)
            return "`" + re.sub(r"\[\d+\]", "[N]", v) + "`"
        if len(v) > 40 or re.search(r"[\d.]+\s*[,:]\s*[\d.]+", v) or "/" in v or "\\" in v:
            return "`…`"
        if re.fullmatch(r"[-+\d.eE ,]+", v) and v.strip():
            return "`N`"
        return m.group(0)

    text = BACKQUOTED.sub(value, text)
    parts = re.split(r"(`[^`]*`)", text)
    for i in range(0, len(parts), 2):
        parts[i] = PATHLIKE.sub("<path>", parts[i])
        parts[i] = re.sub(r"(?<![\w.])[-+]?\d+(\.\d+)?(?![\w.])", "N", parts[i])
        parts[i] = re.sub(r"\"[^\"]{41,}\"", "\"…\"", parts[i])
    text = "".join(parts)
    return text[:220]


PLUGIN_TAGS = {"bsdf", "emitter", "shape", "texture", "sensor", "film", "rfilter", "sampler",
               "integrator", "medium", "phase", "volume", "spectrum"}


def constructs(path, seen=None):
    """What a scene file uses (through its includes too), as names: every plugin as
    `<tag type="...">`, and the constructs issue 32 lists, for the census of how many judged
    files use each."""
    seen = seen if seen is not None else set()
    top = not seen
    seen.add(os.path.abspath(path))
    try:
        root = parse(path).getroot()
    except (ET.ParseError, OSError, ValueError):
        return {"(malformed XML for Python's parser)"}
    found = set()
    for el in root.iter("include"):
        name = os.path.join(os.path.dirname(os.path.abspath(path)), el.get("filename") or "")
        if os.path.isfile(name) and os.path.abspath(name) not in seen:
            found |= constructs(name, seen)
    parent = {c: p for p in root.iter() for c in p}
    for el in root.iter():
        tag = el.tag if isinstance(el.tag, str) else ""
        kind = el.get("type")
        if tag in PLUGIN_TAGS and kind:
            found.add(f'<{tag} type="{kind}">')
            if el.get("name") and parent.get(el) is not None and parent[el] is not root:
                found.add("named nested object (<x name=... type=...> inside a plugin)")
        if tag == "path":
            found.add("<path> element")
        if tag == "include":
            found.add("<include>")
        if tag in ("spectrum", "rgb") and ":" in (el.get("value") or ""):
            found.add("wavelength:value spectrum")
        if tag == "spectrum" and el.get("filename"):
            found.add("<spectrum filename=...>")
        if tag == "spectrum" and len((el.get("value") or "").replace(",", " ").split()) == 3:
            found.add("three-value <spectrum>")
        if tag == "blackbody":
            found.add("<blackbody>")
        if tag.lower() == "lookat" and tag != "lookat":
            found.add(f"<{tag}> (transform operation not lower case)")
        if tag == "lookat" and not el.get("up"):
            found.add("<lookat> without up")
        if tag == "ref" and parent.get(el) is not None:
            found.add(f"<ref> inside <{parent[el].tag}>")
        if tag == "string" and (el.get("name") or "") in ("filter_type", "filterType", "wrap_mode", "wrapMode",
                                                            "wrapModeU", "wrapModeV", "wrap_mode_u"):
            found.add(f"bitmap {el.get('name')}")
        if tag == "string" and el.get("name") in ("intIOR", "extIOR", "int_ior", "ext_ior"):
            found.add(f"named IOR `{el.get('value')}`")
        if tag == "string" and el.get("name") == "material":
            found.add("conductor named material")
        if tag in ("sampler", "film", "rfilter") and parent.get(el) is root:
            found.add(f"top-level <{tag}>")
        if tag == "default":
            found.add("<default>")
    if any(c.tag == "sensor" for c in root):
        found.add("(sensor)")
    if top and "(sensor)" not in found:
        found.add("no <sensor> (in the file or its includes)")
    return found - {"(sensor)"} if top else found


PEEL_PREFIX = ".open-rate-peel."


def peeled_copy(path):
    """A copy of `path` beside it with the constructs that refuse most files today rewritten
    the way Mitsuba reads them, so that the check shows what refuses the file next; None when
    Python cannot parse the file. Rewritten: <path> elements (file names made absolute through
    the search path, includes too), transform operations spelled in any case (`lookAt`),
    wavelength:value spectra (their mean, a grey), three-value spectra (as <rgb>), booleans spelled True/False. The copy is
    a survey aid: remove it after use."""
    try:
        tree = parse(path)
    except (ET.ParseError, OSError, ValueError):
        return None
    root = tree.getroot()
    here = os.path.dirname(os.path.abspath(path))
    defaults = {el.get("name"): el.get("value") for el in root.iter("default") if el.get("name")}
    search = [here]
    for el in list(root):
        if el.tag == "path" and el.get("value"):
            search.append(resolve_folder(substitute(el.get("value"), defaults), here, search))
            root.remove(el)
    for el in root.iter():
        if not isinstance(el.tag, str):
            continue
        if el.tag.lower() in ("lookat", "translate", "rotate", "scale", "matrix") and el.tag != el.tag.lower():
            el.tag = el.tag.lower()
        attr = "filename" if (el.tag == "include" or el.get("filename")) else (
            "value" if el.tag == "string" and (el.get("name") or "").lower() == "filename" else None)
        if attr and el.get(attr) and "$" not in el.get(attr):
            found = find_file(el.get(attr), search)
            if found:
                el.set(attr, os.path.abspath(found))
        value = el.get("value") or ""
        if el.tag in ("spectrum", "rgb") and ":" in value:
            try:
                pairs = [float(p.split(":")[1]) for p in value.replace(";", ",").split(",") if ":" in p]
                el.set("value", f"{sum(pairs) / len(pairs):.6g}")
            except (ValueError, IndexError, ZeroDivisionError):
                pass
        elif el.tag == "spectrum" and len(NUMBER.findall(value)) == 3 and ":" not in value:
            el.tag = "rgb"
        if el.tag == "boolean" and value in ("True", "False", "TRUE", "FALSE"):
            el.set("value", value.lower())
    copy = os.path.join(here, PEEL_PREFIX + os.path.basename(path))
    tree.write(copy, encoding="utf-8", xml_declaration=True)
    return copy


# Coarse groups of the categories, for prioritising: the first pattern that matches wins.
GROUPS = [
    (r"^panic", "panic"),
    (r"^timeout", "timeout"),
    (r"<path> \(a folder searched", "<path> element (adds a folder to the file resolver)"),
    (r"expected one value or three.*`<3 numbers>`", "three-value <spectrum> refused (the message says wavelength:value)"),
    (r"wavelength:value|not a list of numbers", "spectrum given as wavelength:value list"),
    (r"found Object\(Obj", "texture where foton takes a number (the message is a debug dump)"),
    (r"textures \(<texture[^)]*\) are not supported", "texture where foton takes a constant"),
    (r'type="serialized"', "serialized shape"),
    (r"<lookAt>|lookat", "<lookAt> spelling / attributes"),
    (r"missing section \[camera\]", "no usable <sensor> (refused with a TOML [camera] message)"),
    (r"filter_type|filterType", "bitmap filter_type"),
    (r"<rfilter", "reconstruction filter <rfilter>"),
    (r'<film type="[^"]*">`: parameter', "film parameter"),
    (r"not true or false", "boolean spelling (True/False)"),
    (r"comment at .* contains '--'", "XML comment containing '--' (pugixml accepts it)"),
    (r"<volume> in", "<volume> (grid/volume texture) inside a medium or texture"),
    (r"unknown (bsdf|integrator|emitter|shape|texture|sensor|medium|phase) type|unknown integrator",
     "plugin Mitsuba does not have (a fork's own plugin)"),
    (r"<bsdf [^>]*>`: this BSDF is not supported", "BSDF plugin not supported yet"),
    (r"<integrator [^>]*>`: integrator `[^`]*` is not supported", "integrator plugin not supported yet"),
    (r"<emitter [^>]*>`: this emitter is not supported", "emitter plugin not supported yet"),
    (r"<shape [^>]*>`: this shape is not supported", "shape plugin not supported yet"),
    (r"<texture [^>]*>`: this texture is not supported", "texture plugin not supported yet"),
    (r"<sensor [^>]*>`: only the perspective", "sensor plugin other than perspective"),
    (r"parameter `` is not supported", "nested object or <ref> without a name refused as parameter `` (a sensor in a shape, a medium <ref> in a sensor)"),
    (r"parameter `[^`]*` is not supported", "plugin parameter not supported"),
    (r"is not a top-level element", "top-level object foton does not take (<phase>, <film>, ...)"),
    (r"no BSDF with id", "<ref> / id resolution"),
    (r"a shape's emitter must be", "emitter type nested in a shape"),
    (r"no <default name=", "$name without <default>"),
    (r"cannot open|No such file|not found", "file not found by foton's resolver (Mitsuba finds it)"),
    (r"`material` \(Mitsuba", "named medium material"),
    (r"`distribution`", "microfacet distribution name"),
    (r"no integrator plugin", "integrator plugin library missing (build the plugins)"),
]


def group_of(category):
    return next((name for pattern, name in GROUPS if re.search(pattern, category)), "other")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("corpus")
    ap.add_argument("foton")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per check (60)")
    ap.add_argument("--jobs", type=int, default=2, help="checks run at once (2)")
    ap.add_argument("--census-min", type=int, default=3, help="list census items used by at least this many judged files (3)")
    ap.add_argument("--peel", action="store_true",
                    help="for each judged file refused as written, also check a copy (written beside it, then removed) with "
                         "<path>, lookAt spelling, wavelength:value and three-value spectra and True/False rewritten as Mitsuba reads them, "
                         "and report what refuses it next")
    ap.add_argument("--tsv", help="also write one line per file: path, version, assets, as written, lenient, first errors")
    args = ap.parse_args()
    foton = os.path.abspath(args.foton)
    corpus = os.path.abspath(args.corpus)

    if not (os.path.isfile(foton) and os.access(foton, os.X_OK)):
        sys.exit(f"{foton}: not an executable (build it: cargo build --release -p foton)")
    if not os.path.isdir(corpus):
        sys.exit(f"{corpus}: not a folder")
    scenes = []
    for folder, dirs, files in os.walk(corpus):
        dirs.sort()
        for name in sorted(files):
            if name.lower().endswith(".xml") and not name.startswith(PEEL_PREFIX):
                path = os.path.join(folder, name)
                version = scene_root(path)
                if version is not None:
                    scenes.append((path, version))
    if not scenes:
        sys.exit(f"no Mitsuba scene file (root element <scene>) under {corpus}")

    beside = os.path.dirname(foton)
    if not os.environ.get("FOTON_PLUGIN_PATH") and not any(
        n.startswith("libfoton_") or n.startswith("foton_") for n in os.listdir(beside) + (
            os.listdir(os.path.join(beside, "plugins")) if os.path.isdir(os.path.join(beside, "plugins")) else [])):
        print(f"warning: no integrator plugin beside {foton} and no FOTON_PLUGIN_PATH: `foton check` creates "
              "the scene's integrator, so every scene will fail; build them first "
              "(cargo build --release -p foton-path -p foton-bdpt -p foton-sppm -p foton-photon -p foton-vpm)",
              file=sys.stderr)

    workdir = tempfile.mkdtemp(prefix="foton-open-rate-")

    def one(item):
        path, version = item
        missing = missing_assets(path)
        used = constructs(path)
        strict = run_check(foton, path, False, args.timeout, workdir)
        lenient = run_check(foton, path, True, args.timeout, workdir)
        after_peel = None
        if args.peel and not missing and strict[0] != "ok":
            copy = peeled_copy(path)
            if copy:
                try:
                    after_peel = run_check(foton, copy, False, args.timeout, workdir)
                finally:
                    os.remove(copy)
        return path, version, missing, strict, lenient, used, after_peel

    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        results = list(pool.map(one, scenes))
    shutil.rmtree(workdir, ignore_errors=True)

    buckets = ["0.x", "2.x", "3.x", "none", "other"]
    rows = collections.OrderedDict((b, collections.Counter()) for b in buckets)
    hist = {"as written": collections.Counter(), "--lenient": collections.Counter()}
    example = {"as written": {}, "--lenient": {}}
    per_repo = collections.defaultdict(collections.Counter)
    for path, version, missing, strict, lenient, used, after_peel in results:
        r = rows[bucket(version)]
        repo = per_repo[os.path.relpath(path, corpus).split(os.sep)[0]]
        r["files"] += 1
        repo["files"] += 1
        if missing:
            r["assets missing"] += 1
            repo["assets missing"] += 1
            continue
        r["judged"] += 1
        repo["judged"] += 1
        repo["opened"] += strict[0] == "ok"
        repo["lenient"] += lenient[0] == "ok"
        for mode, (status, line) in (("as written", strict), ("--lenient", lenient)):
            key = "opened" if mode == "as written" else "lenient"
            if status == "ok":
                r[key] += 1
                continue
            if status == "panic":
                r["panics " + mode] += 1
            if status == "timeout":
                r["timeouts " + mode] += 1
            cat = {"timeout": f"timeout (> {args.timeout:g} s)", "panic": "panic: " + categorise(line)}.get(status) or categorise(line)
            hist[mode][cat] += 1
            example[mode].setdefault(cat, path)

    def pct(a, b):
        return f"{100.0 * a / b:.0f} %" if b else "-"

    total = collections.Counter()
    print(f"foton: {foton}\ncorpus: {corpus}\ntimeout: {args.timeout:g} s\n")
    header = ["version", "files", "assets missing", "judged", "opened as written", "opened --lenient", "panics (both runs)", "timeouts (both runs)"]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))

    def line(name, r):
        panics = r["panics as written"] + r["panics --lenient"]
        timeouts = r["timeouts as written"] + r["timeouts --lenient"]
        print(f"| {name} | {r['files']} | {r['assets missing']} | {r['judged']} | "
              f"{r['opened']} ({pct(r['opened'], r['judged'])}) | {r['lenient']} ({pct(r['lenient'], r['judged'])}) | "
              f"{panics} | {timeouts} |")

    for name, r in rows.items():
        if r["files"]:
            line(name, r)
            total.update(r)
    line("all", total)

    print("\nBy repository (the corpus's first folder level)")
    print("| repository | files | assets missing | judged | opened as written | opened --lenient |")
    print("|---|---|---|---|---|---|")
    for repo, r in sorted(per_repo.items()):
        print(f"| {repo} | {r['files']} | {r['assets missing']} | {r['judged']} | {r['opened']} | {r['lenient']} |")

    usage = collections.Counter()
    usage_open = collections.Counter()
    usage_example = {}
    for path, version, missing, strict, lenient, used, after_peel in results:
        if missing:
            continue
        for c in used:
            usage[c] += 1
            usage_open[c] += strict[0] == "ok"
            if strict[0] != "ok":
                usage_example.setdefault(c, path)
    print("\nCensus: judged files using each plugin or construct (a file counts once per item), and how many"
          " of those open as written; what no judged file opens with is an upper bound on what fixing it gains")
    print("| files | open as written | plugin or construct | example (not opening) |")
    print("|---|---|---|---|")
    for c, count in sorted(usage.items(), key=lambda kv: (-kv[1], kv[0])):
        if count >= args.census_min:
            shown = c.replace("|", "\\|")
            ex = os.path.relpath(usage_example[c], corpus) if c in usage_example else "-"
            print(f"| {count} | {usage_open[c]} | {shown} | {ex} |")

    for mode in ("as written", "--lenient"):
        n = sum(hist[mode].values())
        grouped = collections.Counter()
        group_cats = collections.defaultdict(int)
        for cat, count in hist[mode].items():
            grouped[group_of(cat)] += count
            group_cats[group_of(cat)] += 1
        print(f"\nFailures {mode} (judged files): {n}, by group")
        print("| count | group | categories |")
        print("|---|---|---|")
        for g, count in sorted(grouped.items(), key=lambda kv: (-kv[1], kv[0])):
            print(f"| {count} | {g} | {group_cats[g]} |")
        print(f"\nFailures {mode} (judged files): {n}, first error line by category")
        print("| count | category | example |")
        print("|---|---|---|")
        for cat, count in sorted(hist[mode].items(), key=lambda kv: (-kv[1], kv[0])):
            shown = cat.replace("|", "\\|")
            print(f"| {count} | {shown} | {os.path.relpath(example[mode][cat], corpus)} |")

    if args.peel:
        peel_hist = collections.Counter()
        peel_example = {}
        opened = 0
        tried = 0
        for path, version, missing, strict, lenient, used, after_peel in results:
            if after_peel is None:
                continue
            tried += 1
            if after_peel[0] == "ok":
                opened += 1
                continue
            cat = {"timeout": f"timeout (> {args.timeout:g} s)", "panic": "panic: " + categorise(after_peel[1])}.get(
                after_peel[0]) or categorise(after_peel[1])
            peel_hist[cat] += 1
            peel_example.setdefault(cat, path)
        print(f"\nAfter peeling (<path>, lookAt spelling, wavelength:value and three-value spectra, True/False rewritten in a copy): "
              f"{tried} judged files refused as written, {opened} of them open; what refuses the others next")
        print("| count | category | group | example |")
        print("|---|---|---|---|")
        for cat, count in sorted(peel_hist.items(), key=lambda kv: (-kv[1], kv[0])):
            shown = cat.replace("|", "\\|")
            print(f"| {count} | {shown} | {group_of(cat)} | {os.path.relpath(peel_example[cat], corpus)} |")

    if args.tsv:
        with open(args.tsv, "w", encoding="utf-8") as out:
            out.write("file\tversion\tassets\tas written\tlenient\tpeeled\terror as written\terror --lenient\terror peeled\n")
            for path, version, missing, strict, lenient, used, after_peel in results:
                assets = "missing: " + ", ".join(missing[:3]) if missing else "ok"
                peel = after_peel or ("-", "")
                out.write("\t".join([os.path.relpath(path, corpus), version or "-", assets, strict[0], lenient[0],
                                     peel[0], strict[1].replace("\t", " "), lenient[1].replace("\t", " "),
                                     peel[1].replace("\t", " ")]) + "\n")


if __name__ == "__main__":
    main()
