"""foton from Python: load a scene, render it into a numpy array, write, read and compare images.

    >>> import foton
    >>> scene = foton.load("scenes/cornell-box.toml", **{"render.spp": 16})
    >>> image = scene.render(spp=4, seed=1)      # numpy float32, (height, width, 3), linear
    >>> foton.write(image, "box.exr")            # as `foton render -o box.exr` writes it

The package calls the code of the ``foton`` program (the same loader, plugins, renderer and
image writer), so an image rendered here equals the one ``foton render`` writes for the same
scene, integrator and seed, bit for bit. See python/README.md.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, NamedTuple, Union

import numpy as np

from . import _foton
from ._errors import (
    FileError,
    FotonError,
    FotonWarning,
    PluginError,
    RenderError,
    SceneError,
    UsageError,
)

__all__ = [
    "load",
    "loads",
    "Scene",
    "write",
    "read",
    "to_display",
    "compare",
    "Errors",
    "plugins",
    "Plugin",
    "build_info",
    "PLUGIN_DIR",
    "FotonError",
    "SceneError",
    "PluginError",
    "FileError",
    "UsageError",
    "RenderError",
    "FotonWarning",
]

__version__ = _foton.build_info()["core_version"]

#: The integrator plugins that come with the package. Searched after the program's search path
#: (``plugin_dirs``, ``FOTON_PLUGIN_PATH``, the folder of the running executable and its
#: ``plugins/`` subfolder), so a plugin found there first is used instead.
PLUGIN_DIR = Path(__file__).resolve().parent / "plugins"

PathLike = Union[str, "os.PathLike[str]"]
#: ``progress(phase, done, total)``
ProgressCallback = Callable[[str, int, int], Any]


def _extra_dirs() -> list[str]:
    return [str(PLUGIN_DIR)]


def _dirs(plugin_dirs: Iterable[PathLike]) -> list[str]:
    if isinstance(plugin_dirs, (str, os.PathLike)):
        plugin_dirs = [plugin_dirs]
    return [os.fspath(d) for d in plugin_dirs]


# --- overrides: Python values as the TOML values of `--set KEY.PATH=VALUE` -------------------


def _toml_string(s: str) -> str:
    # JSON's escapes are TOML's (\" \\ \n \t \uXXXX...), except that TOML also escapes DEL.
    return json.dumps(s, ensure_ascii=False).replace("\x7f", "\\u007F")


def _toml(value: Any, key: str) -> str:
    """The TOML text of a Python value, for an override of ``key``."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    elif isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, os.PathLike):
        return _toml_string(os.fspath(value))
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml(v, key) for v in value) + "]"
    raise TypeError(
        f"override `{key}`: cannot be a {type(value).__name__}; "
        "use a bool, int, float, str or a list of them"
    )


def _overrides(values: Mapping[str, Any], prefix: str = "") -> list[str]:
    """``{"render.spp": 16, "integrators": {"photon": {"k": 50}}}`` ->
    ``["render.spp=16", "integrators.photon.k=50"]``: dotted keys as ``--set`` takes them, a
    dict value merged key by key."""
    out: list[str] = []
    for key, value in values.items():
        if not isinstance(key, str):
            raise TypeError(f"override keys are dotted key paths (str), not {key!r}")
        path = f"{prefix}.{key}" if prefix else key
        if isinstance(value, Mapping):
            out.extend(_overrides(value, path))
        else:
            out.append(f"{path}={_toml(value, path)}")
    return out


def _warn(messages: Iterable[str], stacklevel: int) -> None:
    for m in messages:
        warnings.warn(m, FotonWarning, stacklevel=stacklevel + 1)


# --- scenes ------------------------------------------------------------------------------------


def _defines(defines: Mapping[str, Any] | None) -> list[str]:
    out = []
    for name, value in (defines or {}).items():
        if isinstance(value, bool):
            value = "true" if value else "false"
        out.append(f"{name}={value}")
    return out


def load(
    path: PathLike,
    *,
    defines: Mapping[str, Any] | None = None,
    lenient: bool = False,
    plugin_dirs: Iterable[PathLike] = (),
    strict: bool = False,
    **overrides: Any,
) -> "Scene":
    """Loads a scene file and creates its integrator, as ``foton render`` does: a TOML scene,
    or a Mitsuba 3 XML scene (``.xml``).

    ``overrides`` set scene values by their dotted key paths, like the program's ``--set``:
    ``foton.load("s.toml", **{"render.spp": 16, "integrators.photon.k": 50})``. A keyword
    whose value is a dict is merged key by key: ``foton.load("s.toml", render={"spp": 16})``
    is the same as ``**{"render.spp": 16}``. Values are Python values (bool, int, float, str,
    lists of them): a str is a TOML string.

    For a Mitsuba XML scene, ``defines`` set its ``<default>`` values (the program's
    ``-D NAME=VALUE``, Mitsuba's ``mi.load_file(path, **params)``): ``defines={"spp": 16}``;
    ``lenient=True`` leaves out what foton cannot render yet (each listed in a warning)
    instead of refusing the scene (``--lenient``). Overrides apply to XML scenes too, to the
    TOML scene the XML reads as.

    ``plugin_dirs`` are searched for plugins first (``--plugin-dir``), then
    ``FOTON_PLUGIN_PATH``, the running executable's folder and its ``plugins/``, then the
    package's own plugins (:data:`PLUGIN_DIR`). ``strict``: unknown fields, and Mitsuba XML parameters foton ignores, are errors.

    Raises :class:`SceneError` (file, line, key), :class:`PluginError`, :class:`FileError`,
    :class:`UsageError`. Unknown fields are :class:`FotonWarning` warnings.
    """
    native = _foton.load(
        os.fspath(path),
        None,
        _overrides(overrides),
        _defines(defines),
        bool(lenient),
        _dirs(plugin_dirs),
        _extra_dirs(),
        strict,
    )
    scene = Scene(native)
    _warn(native.warnings, stacklevel=2)
    return scene


def loads(
    text: str,
    base_dir: PathLike | None = None,
    *,
    plugin_dirs: Iterable[PathLike] = (),
    strict: bool = False,
    **overrides: Any,
) -> "Scene":
    """Loads a scene from TOML text, as :func:`load` loads a file (for a Mitsuba XML scene,
    write it to a file and :func:`load` that).

    Relative paths in the scene (meshes, the film output) are resolved against ``base_dir``
    (default: the current folder); messages name the scene ``<base_dir>/<string>``.
    """
    name = "<string>" if base_dir is None else os.path.join(os.fspath(base_dir), "<string>")
    native = _foton.load(
        name, text, _overrides(overrides), [], False, _dirs(plugin_dirs), _extra_dirs(), strict
    )
    scene = Scene(native)
    _warn(native.warnings, stacklevel=2)
    return scene


class Scene:
    """A loaded scene and its integrator (from :func:`load` or :func:`loads`)."""

    def __init__(self, native: Any) -> None:
        self._native = native
        #: What the last :meth:`render` did: a dict with ``seconds``, ``samples``, ``spp``,
        #: ``iterations`` (a progressive integrator's; 0 for the others),
        #: ``iterations_planned``, ``photons``, ``rays``, ``threads``, ``integrator`` (its
        #: description), ``interrupted`` and ``warnings``.
        self.last_render: dict[str, Any] | None = None

    file = property(lambda self: Path(self._native.file), doc="The scene file.")
    width = property(lambda self: self._native.width, doc="Image width in pixels.")
    height = property(lambda self: self._native.height, doc="Image height in pixels.")
    spp = property(lambda self: self._native.spp, doc="render.spp")
    seed = property(lambda self: self._native.seed, doc="render.seed")
    sampler = property(lambda self: self._native.sampler, doc="render.sampler")
    max_depth = property(lambda self: self._native.max_depth, doc="render.max_depth")
    integrator = property(lambda self: self._native.integrator, doc="render.integrator")
    description = property(
        lambda self: self._native.description,
        doc="The integrator and its parameters in force: 'photon(k = 50, ...)'.",
    )
    output = property(lambda self: Path(self._native.output), doc="film.output")
    warnings = property(lambda self: list(self._native.warnings), doc="The load's warnings.")

    @property
    def parameters(self) -> dict[str, Any]:
        """The integrator's parameters in force (defaults included), by name."""
        return dict(self._native.parameters)

    @property
    def display(self) -> dict[str, Any]:
        """The scene's ``[film] exposure`` and ``tonemap``, as :func:`write` takes them:
        ``foton.write(image, "x.png", **scene.display)`` writes the PNG the program would."""
        exposure, tonemap = self._native.display
        return {"exposure": exposure, "tonemap": tonemap}

    def __repr__(self) -> str:
        return f"<foton.Scene {str(self.file)!r}: {self.width}x{self.height}, {self.description}>"

    def render(
        self,
        integrator: str | None = None,
        spp: int | None = None,
        seed: int | None = None,
        threads: int | None = None,
        params: Mapping[str, Any] | None = None,
        sampler: str | None = None,
        *,
        progress: bool | ProgressCallback | None = True,
    ) -> np.ndarray:
        """Renders the scene; returns its linear radiance, a float32 array (height, width, 3).

        ``integrator``, ``spp`` and ``seed`` override the scene's as the program's
        ``--integrator``, ``--spp`` and ``--seed`` do; ``params`` sets the integrator's
        parameters (``{"k": 50}`` is ``--set integrators.NAME.k=50``). ``threads``: worker
        threads (default: all cores; the image does not depend on it). ``sampler``:
        ``"independent"``, ``"stratified"`` or ``"sobol"`` (``render.sampler``).

        ``progress``: ``True`` shows a tqdm bar per phase if tqdm is installed; a callable is
        called as ``progress(phase, done, total)`` from the calling thread while the render
        runs: with ``done = 0`` when a phase ("photons", "pixels", "iterations") begins, then as
        it advances (at most every 25 ms), and with its last count when it ends; an exception
        it raises stops the render and is raised. ``False`` or ``None``: nothing.

        The GIL is released while the render runs. Ctrl-C (SIGINT in the main thread) stops
        it within a fraction of a second and raises ``KeyboardInterrupt`` with the partial
        image attached as ``e.image`` (each pixel the mean of the samples it got; for a
        progressive integrator, the estimate of the iterations done) and the render's info as
        ``e.render_info`` (``interrupted`` is True); the same as the image ``foton render``
        writes when interrupted.
        """
        sets: dict[str, Any] = {}
        name = integrator if integrator is not None else self.integrator
        if params:
            sets.update({f"integrators.{name}.{k}": v for k, v in params.items()})
        if integrator is not None:
            sets["render.integrator"] = integrator
        if spp is not None:
            sets["render.spp"] = spp
        if seed is not None:
            sets["render.seed"] = seed
        if sampler is not None:
            sets["render.sampler"] = sampler
        if threads is not None and (isinstance(threads, bool) or int(threads) < 1):
            raise ValueError(f"threads must be at least 1, not {threads!r}")
        bars = None
        if progress is True:
            bars = _tqdm_progress()
            callback = bars
        elif progress is False or progress is None:
            callback = None
        elif callable(progress):
            callback = progress
        else:
            raise TypeError("progress must be True, False, None or a callable")
        try:
            image, info = self._native.render(
                _overrides(sets), None if threads is None else int(threads), callback
            )
        except BaseException as e:
            info = getattr(e, "render_info", None)
            if info is not None:
                self.last_render = dict(info)
            raise
        finally:
            if bars is not None:
                bars.close()
        self.last_render = dict(info)
        _warn(info["warnings"], stacklevel=2)
        return image


def _tqdm_progress() -> Any:
    """A progress callback drawing one tqdm bar per phase, or None without tqdm."""
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None

    class Bars:
        def __init__(self) -> None:
            self.bar: Any = None
            self.phase: str | None = None

        def __call__(self, phase: str, done: int, total: int) -> None:
            # A phase begins with done = 0 (see Scene.render): a new bar.
            if self.bar is None or phase != self.phase or done < self.bar.n or total != self.bar.total:
                self.close()
                self.bar = tqdm(total=total, desc=phase, leave=False)
                self.phase = phase
            self.bar.update(done - self.bar.n)

        def close(self) -> None:
            if self.bar is not None:
                self.bar.close()
                self.bar = None

    return Bars()


# --- images --------------------------------------------------------------------------------------


def _image(a: Any, what: str) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"{what}: expected an RGB image of shape (height, width, 3), not {a.shape}")
    return a


def write(image: Any, path: PathLike, exposure: float = 0.0, tonemap: str = "clamp") -> None:
    """Writes an image as ``foton render`` writes one: ``.exr`` as linear float32, ``.png`` as
    8-bit sRGB after ``exposure`` (stops) and ``tonemap`` (``"clamp"`` or ``"filmic"``);
    atomically. ``foton.write(image, "x.png", **scene.display)`` uses the scene's ``[film]``
    settings, as the program does."""
    a = _image(image, "write")
    h, w, _ = a.shape
    _foton.write(os.fspath(path), a.tobytes(), w, h, float(exposure), str(tonemap))


def to_display(image: Any, exposure: float = 0.0, tonemap: str = "clamp") -> np.ndarray:
    """The 8-bit sRGB image (uint8, (height, width, 3)) that :func:`write` puts in a PNG: for
    showing a render, ``plt.imshow(foton.to_display(image, **scene.display))``."""
    a = _image(image, "to_display")
    h, w, _ = a.shape
    return _foton.to_display(a.tobytes(), w, h, float(exposure), str(tonemap))


def read(path: PathLike) -> np.ndarray:
    """Reads an image as linear radiance, float32 (height, width, 3): an EXR as stored, a PNG
    decoded from sRGB (as ``foton compare --reference`` reads a reference)."""
    return _foton.read(os.fspath(path))


class Errors(NamedTuple):
    """An image's error against a reference, as ``foton compare`` computes it."""

    #: Relative MSE: mean over pixels and channels of (x - r)^2 / (r^2 + 0.01).
    rel_mse: float
    #: (mean x - mean r) / mean r; NaN when the reference is black (null in the program's JSON).
    bias: float


def compare(
    images: Any,
    reference: Any,
    report: PathLike | None = None,
    *,
    exposure: float = 0.0,
    tonemap: str = "clamp",
) -> Any:
    """``foton compare``'s error figures (``rel_mse``, ``bias``) of images against a reference.

    ``reference`` is an array or an image file. ``images`` is one array (returns one
    :class:`Errors`), a dict of arrays (returns a dict of the same keys) or a list of arrays
    (returns a list).

    With ``report="x.html"`` also writes ``foton compare --report``'s interactive page: a tab
    per image (named by the dict's keys; ``image 1``, ``image 2``... for a list), then
    ``reference``, with the error images (and FLIP) against it, shown through ``exposure``
    (stops) and ``tonemap`` ("clamp" or "filmic").
    """
    if isinstance(reference, (str, os.PathLike)):
        reference = read(reference)
    ref = _image(reference, "reference")
    ref_bytes = ref.tobytes()
    arrays: list[tuple[str, np.ndarray]] = []

    def one(x: Any, what: str, name: str) -> Errors:
        a = _image(x, what)
        if a.shape != ref.shape:
            raise ValueError(f"{what}: shape {a.shape} is not the reference's {ref.shape}")
        arrays.append((name, a))
        return Errors(*_foton.errors(a.tobytes(), ref_bytes, ref.shape[1], ref.shape[0]))

    if isinstance(images, Mapping):
        result: Any = {k: one(v, f"image {k!r}", str(k)) for k, v in images.items()}
    elif isinstance(images, (list, tuple)):
        result = [one(v, f"image {i}", f"image {i + 1}") for i, v in enumerate(images)]
    else:
        result = one(images, "image", "image")
    if report is not None:
        names = [n for n, _ in arrays]
        if "reference" in names:
            raise ValueError("report: an image named 'reference' would hide the reference's tab")
        _foton.report(
            os.fspath(report),
            names,
            [a.tobytes() for _, a in arrays],
            ref_bytes,
            ref.shape[1],
            ref.shape[0],
            float(exposure),
            tonemap,
            "foton.compare",
            "",
        )
    return result


# --- plugins -------------------------------------------------------------------------------------


class Plugin(NamedTuple):
    name: str
    #: "integrator" or "kernel"
    kind: str
    description: str
    file: Path


class PluginList(list):
    """The plugins found (a list of :class:`Plugin`), with the folders searched
    (``search_path``) and the files skipped with the reason (``skipped``: (file, message))."""

    search_path: list[Path]
    skipped: list[tuple[Path, str]]


def plugins(plugin_dirs: Iterable[PathLike] = ()) -> PluginList:
    """The plugins on the search path, as ``foton plugins`` lists them (see :func:`load`)."""
    found = _foton.plugins(_dirs(plugin_dirs), _extra_dirs())
    out = PluginList(
        Plugin(name, kind, description, Path(file))
        for name, kind, description, file in found["plugins"]
    )
    out.search_path = [Path(d) for d in found["search_path"]]
    out.skipped = [(Path(f), m) for f, m in found["skipped"]]
    return out


def build_info() -> dict[str, Any]:
    """What plugins are checked against: ``core_version``, ``plugin_api``, ``rustc`` and
    ``build_id`` (the last line of ``foton plugins``). A plugin loads only if its build id is
    this one."""
    return dict(_foton.build_info())
