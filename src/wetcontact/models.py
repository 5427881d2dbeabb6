"""ForceCurve, the Model interface and the model registry.

Every model has one call, ``model.force(scene, gaps=None, preset="default") -> ForceCurve``,
plus metadata (name, fidelity level, validity range, declared convergence order, resolution
presets). Models live in the plain dict :data:`MODELS`; tests and reports iterate over it.

Sign convention (DESIGN.md): a force is the axial force on the sphere, positive when it
pushes the surfaces apart. Viscous resistance to approach is positive; a bridge's
capillary attraction is negative.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from wetcontact.errors import InputError, SolverError, ValidityError, short_repr
from wetcontact.scene import Scene

PRESETS = ("fast", "default", "accurate")


@dataclass(frozen=True, eq=False)
class ForceCurve:
    """Forces along a sequence of gaps, with extras, diagnostics and provenance.

    Attributes
    ----------
    case
        Scene name.
    model
        Name of the model that produced the curve.
    gap
        Surface gaps S (m), shape (n,).
    force_viscous, force_capillary
        Axial force components (N), shape (n,), positive = pushing the surfaces apart;
        ``None`` where the model does not model that component (not zero). Both are
        ``None`` only for a model of a derived quantity alone, carried in ``extras`` (a
        refitted rupture-distance closure: ``rupture_distance``, no force).
    extras
        Per-gap quantities, each shape (n,): e.g. ``laplace_pressure`` (Pa), ``neck_radius``
        (m), ``filling_angle`` (rad), ``wetted_radius`` (m), ``rupture_distance`` (m).
    error_estimate
        A-priori or a-posteriori relative error estimate per gap, or ``None``.
    diagnostics
        What the solver did: iterations, residuals, dofs, wall time (``wall_time_s``).
        ``outside_domain`` (a refitted closure, :class:`wetcontact.calibrate.CalibratedClosure`):
        how many gaps lie outside its calibrated domain and why; the forces and extras are
        NaN at those gaps, and only there, and only with this key (otherwise every value is
        finite).
    settings
        Everything besides the scene that changes a number (preset, resolution, ...).
    provenance
        Package and library versions, git commit, command; filled by :func:`provenance`.
    """

    case: str
    model: str
    gap: np.ndarray
    force_viscous: np.ndarray | None
    force_capillary: np.ndarray | None
    extras: Mapping[str, np.ndarray] = field(default_factory=dict)
    error_estimate: np.ndarray | None = None
    diagnostics: Mapping[str, Any] = field(default_factory=dict)
    settings: Mapping[str, Any] = field(default_factory=dict)
    provenance: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        gap = np.array(self.gap, dtype=float)  # a copy, frozen below like the forces
        if gap.ndim != 1 or gap.size == 0:
            raise SolverError(f"ForceCurve '{self.model}': gap must be a non-empty 1-D array")
        gap.setflags(write=False)
        object.__setattr__(self, "gap", gap)
        if self.force_viscous is None and self.force_capillary is None and not self.extras:
            raise SolverError(f"ForceCurve '{self.model}': no force component given")
        for name in ("force_viscous", "force_capillary", "error_estimate"):
            val = getattr(self, name)
            if val is not None:
                object.__setattr__(self, name, self._checked(name, val, gap.size))
        object.__setattr__(
            self, "extras", {k: self._checked(k, v, gap.size) for k, v in self.extras.items()}
        )

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Unpickling (a curve back from a sweep worker): the arrays read-only again, as
        :meth:`__post_init__` leaves them (pickle restores them writable)."""
        for value in (*state.values(), *state.get("extras", {}).values()):
            if isinstance(value, np.ndarray):
                value.setflags(write=False)
        self.__dict__.update(state)

    def _checked(self, name: str, val: Any, n: int) -> np.ndarray:
        arr = np.asarray(val, dtype=float) + 0.0  # a copy, and -0.0 (a negated 0) is 0.0
        if arr.shape != (n,):
            raise SolverError(
                f"ForceCurve '{self.model}': {name} has shape {arr.shape}, expected ({n},)"
            )
        ok = np.isfinite(arr)
        if self.diagnostics.get("outside_domain"):  # NaN: a gap outside a refit's domain
            ok |= np.isnan(arr)
        if not np.all(ok):
            bad = self.gap[~ok]
            raise SolverError(
                f"model '{self.model}' produced non-finite {name} at gaps {bad[:3].tolist()} m"
            )
        arr.setflags(write=False)
        return arr

    @property
    def force_total(self) -> np.ndarray | None:
        """Sum of the modelled components (N); ``None`` when the curve models no force
        (its ``extras`` alone)."""
        parts = [f for f in (self.force_viscous, self.force_capillary) if f is not None]
        return np.sum(parts, axis=0) if parts else None

    def to_json_dict(self) -> dict[str, Any]:
        """The CLI's ``--json`` object (DESIGN.md): lists in SI units."""

        def lst(a: np.ndarray | None) -> list[float] | None:
            return None if a is None else [float(x) for x in a]

        out: dict[str, Any] = {
            "case": self.case,
            "model": self.model,
            "gap": lst(self.gap),
            "force_viscous": lst(self.force_viscous),
            "force_capillary": lst(self.force_capillary),
            "force_total": lst(self.force_total),
        }
        out.update({k: lst(v) for k, v in self.extras.items()})
        out["wall_time_s"] = float(self.diagnostics.get("wall_time_s", 0.0))
        out["error_estimate"] = lst(self.error_estimate)
        out["settings"] = dict(self.settings)
        out["diagnostics"] = {k: _jsonable(v) for k, v in self.diagnostics.items()}
        out["provenance"] = dict(self.provenance)
        return out

    def to_dataframe(self) -> Any:
        """The curve as a ``pandas.DataFrame``, one row per gap (pandas is optional).

        Columns: ``gap`` (m), then ``force_viscous``, ``force_capillary`` and
        ``force_total`` (N, positive = pushing the surfaces apart) for the components the
        model models (a component it does not model has no column, rather than zeros or
        NaN), then ``error_estimate`` when there is one and every extra under its own name.
        ``DataFrame.attrs`` holds ``case``, ``model`` and ``settings``.

        Raises
        ------
        ImportError
            pandas is not installed (``pip install pandas``).
        """
        try:
            import pandas as pd
        except ImportError:
            raise ImportError("ForceCurve.to_dataframe needs pandas, which wetcontact does not "
                              "install: pip install pandas (or use to_json_dict())") from None
        cols: dict[str, np.ndarray] = {"gap": self.gap}
        for name in ("force_viscous", "force_capillary", "force_total", "error_estimate"):
            if (arr := getattr(self, name)) is not None:
                cols[name] = arr
        cols.update({k: v for k, v in self.extras.items() if k not in cols})
        df = pd.DataFrame({k: np.array(v) for k, v in cols.items()})
        df.attrs.update(case=self.case, model=self.model, settings=dict(self.settings))
        return df


def _jsonable(v: Any) -> Any:
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, np.generic):
        return v.item()
    return v


class Model:
    """Base of every model. Subclasses set the metadata and implement :meth:`_force`.

    Class attributes
    ----------------
    name : str
        Registry key.
    level : int
        Fidelity level (0 closed form, 1 lubrication PDE, 2 thin film, 3 FEM).
    component : str
        ``"viscous"``, ``"capillary"`` or ``"both"``.
    validity : str
        Human-readable validity range (shown by ``wetcontact models``).
    order : float or None
        Declared convergence order of the force under refinement (None for closed forms).
    reference : str
        The source of the model's equation.
    source : str
        The paper the model comes from (a solver: its method and the papers it is checked
        against; a calibrated closure: what it was fitted to), shown by ``wetcontact
        models``. A refit loaded from a file (:class:`wetcontact.calibrate.CalibratedClosure`)
        has that file as its source.
    cost : float
        Rough wall time per gap (s), to rank models of one level by cost.
    error_bound : dict
        Solvers: preset name -> relative error bound of the force within the validity
        range, measured in the tests or benchmarks (used by model selection).
    saves_fields : bool
        True for field solvers that accept ``save_fields=DIR`` (VTU output).
    reference_rank : dict
        Component -> rank of the model as the reference for that component (higher is
        trusted more; absent: never a reference). :func:`wetcontact.compare.reference_for`
        picks the highest-ranked curve present; nothing else keeps a list of references.
    selectable : bool
        False for a model whose force depends on the motion's history and not on the gap
        alone (``stokes-dynamic`` starts from a static bridge at a given gap): model
        selection and refusal hints (:func:`model_instead`) leave it out; it runs by name.
    """

    name: ClassVar[str] = ""
    level: ClassVar[int] = 0
    component: ClassVar[str] = "viscous"
    validity: ClassVar[str] = ""
    order: ClassVar[float | None] = None
    reference: ClassVar[str] = ""
    source: ClassVar[str] = ""
    cost: ClassVar[float] = 1e-6
    error_bound: ClassVar[Mapping[str, float]] = {}
    saves_fields: ClassVar[bool] = False
    reference_rank: ClassVar[Mapping[str, int]] = {}
    selectable: ClassVar[bool] = True
    presets: ClassVar[Mapping[str, Mapping[str, Any]]] = {p: {} for p in PRESETS}

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """Wrap a subclass's :meth:`check` so its refusal hints stay consistent."""
        super().__init_subclass__(**kwargs)
        if "check" in cls.__dict__:
            cls.check = _consistent_hint(cls.__dict__["check"])  # type: ignore[method-assign]

    def check(self, scene: Scene) -> None:
        """Raise :class:`ValidityError` if the scene is outside this model's validity."""

    def applicable(self, scene: Scene) -> str | None:
        """``None`` if the model applies to ``scene``, else the reason why not."""
        try:
            self.check(scene)
        except InputError as exc:  # ValidityError, or a scene value the model rejects
            return str(exc)
        return None

    def force(self, scene: Scene, gaps: Any = None, preset: str = "default",
              **settings: Any) -> ForceCurve:
        """Force on the sphere at the scene's gaps (or at ``gaps``).

        Parameters
        ----------
        scene
            The contact (:class:`~wetcontact.scene.Scene`, e.g. from
            :func:`~wetcontact.scene.load_case` or :func:`~wetcontact.scene.scene_from_dict`).
        gaps
            Surface gaps S (m) overriding the scene's: a number, a sequence or a 1-D array,
            each in [max(1e-12 m, 1e-9 R_s), 100 R] (:func:`~wetcontact.scene.min_gap`).
        preset
            Resolution preset: ``fast``, ``default`` or ``accurate`` (a closure gives the
            same values at each; ``calibrated-capillary`` sums two-angle tables in double
            precision at ``accurate``).
        **settings
            Model options overriding the preset's (documented per model).

        Returns
        -------
        ForceCurve
            Forces in N on the sphere, positive = pushing the surfaces apart, with the
            model's extras, error estimate, diagnostics (``wall_time_s``), settings and
            provenance.

        Raises
        ------
        InputError
            ``scene`` is not a Scene, an unknown preset, a bad gap or option.
        ValidityError
            The scene is outside the model's validity (the message names the model to use).
        SolverError
            The solver failed.
        """
        if not isinstance(scene, Scene):
            raise InputError(f"model '{self.name}': scene = {short_repr(scene)}; allowed: a "
                             "Scene (wetcontact.scene.load_case or scene_from_dict)")
        if not isinstance(preset, str) or preset not in self.presets:
            raise InputError(f"model '{self.name}': preset = {short_repr(preset)}; allowed: "
                             + ", ".join(self.presets))
        if settings and not any(self.presets.values()):  # a model without options
            raise InputError(f"model '{self.name}': unknown option(s) {sorted(settings)}; "
                             "allowed: none (a closed form)")
        if gaps is not None:
            scene = scene.with_gaps(_gap_list(self.name, gaps))
        opts = {**self.presets[preset], **settings}
        self.check_options(scene, opts)
        t0 = time.perf_counter()
        curve = self._force(scene, preset=preset, **opts)
        wall = time.perf_counter() - t0
        diag = {**curve.diagnostics, "wall_time_s": wall}
        return ForceCurve(
            case=scene.name, model=self.name, gap=curve.gap,
            force_viscous=curve.force_viscous, force_capillary=curve.force_capillary,
            extras=curve.extras, error_estimate=curve.error_estimate, diagnostics=diag,
            settings=self.settings_for(preset, **settings),
            provenance=provenance(),
        )

    def check_options(self, scene: Scene, opts: dict[str, Any]) -> None:
        """Refuse ``scene`` at the options ``opts`` (a preset's merged with the caller's):
        :meth:`check`, since most models' validity does not depend on their options. A
        model whose does overrides this, and its :meth:`check` is this at the default
        preset's options: what selection and the refusal hints see."""
        self.check(scene)

    def settings_for(self, preset: str = "default", **settings: Any) -> dict[str, Any]:
        """The ``settings`` a curve computed at ``preset`` with ``settings`` will carry.

        It is known before the solve, so the store's content key of a point can be found
        without running the model (sweeps reuse stored points by it).
        """
        opts = {**self.presets[preset], **settings}
        return {"preset": preset, **{k: _jsonable(v) for k, v in opts.items()}}

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        raise NotImplementedError


MODELS: dict[str, Model] = {}


def _gap_list(model: str, gaps: Any) -> list[float]:
    """``gaps`` given to :meth:`Model.force` as a list of floats (m), or an InputError: a
    number or a flat sequence of numbers (numpy scalars and arrays included); not a bool,
    None, a string or a range table. Their values are checked by ``Scene.with_gaps``."""
    from wetcontact.scene import plain_number

    items = list(gaps) if isinstance(gaps, list | tuple | np.ndarray) else [gaps]
    ok = all(isinstance(g := plain_number(x), int | float) and not isinstance(g, bool)
             for x in items)
    if ok:
        try:
            return [float(x) for x in np.asarray(items, dtype=float).ravel()]
        except (TypeError, ValueError, OverflowError):
            pass
    raise InputError(f"model '{model}': gaps = {short_repr(gaps)}; allowed: a number or a "
                     "list of numbers, surface gaps in m")


def _accepts(model: Model, scene: Scene) -> bool:
    """True if the model's own (unwrapped) check accepts the scene."""
    try:
        getattr(type(model).check, "__wrapped__", type(model).check)(model, scene)
    except InputError:
        return False
    return True


def model_instead(scene: Scene, component: str, exclude: str | tuple[str, ...] = ""
                  ) -> str | None:
    """The most faithful model that accepts ``scene`` for ``component`` (every model module
    imported first: a closure may refuse before the solvers are loaded).

    Ranked by the model's ``reference_rank`` for the component, then by fidelity level;
    ``component = "both"`` takes a model of either component; ``exclude`` names models
    not to name. ``None`` if none accepts.
    """
    skip = (exclude,) if isinstance(exclude, str) else exclude

    def serves(m: Model) -> bool:
        return component == "both" or m.component in (component, "both")

    cands = [m for m in load_all().values()
             if m.name not in skip and m.selectable and serves(m)]
    cands.sort(key=lambda m: (-max(m.reference_rank.values(), default=0), -m.level, m.name))
    return next((m.name for m in cands if _accepts(m, scene)), None)


def _consistent_hint(check: Any) -> Any:
    """Decorate a model's ``check``: a refusal that names a model which refuses the same
    scene names instead the most faithful model that accepts it (:func:`model_instead`),
    or none, so a user is never sent from one refusal to another."""
    import functools

    @functools.wraps(check)
    def wrapped(self: Model, scene: Scene) -> None:
        if getattr(_HINTS, "busy", False):  # a check called while a hint is being repaired
            check(self, scene)
            return
        _HINTS.busy = True
        try:
            try:
                check(self, scene)
            except ValidityError as exc:
                alt = exc.use_instead
                if alt is not None and alt not in MODELS:
                    load_all()  # a closure refusing before the solvers were imported
                if alt is None or (alt in MODELS and alt != self.name
                                   and _accepts(MODELS[alt], scene)):
                    raise
                alt = model_instead(scene, self.component, exclude=self.name)
                reason = exc.reason if alt else (
                    f"{exc.reason}; no registered model of its component covers this scene")
                raise ValidityError(self.name, reason, alt) from None
        finally:
            _HINTS.busy = False

    return wrapped


_HINTS = threading.local()


def register(cls: type[Model]) -> type[Model]:
    """Class decorator: instantiate and add to :data:`MODELS` under ``cls.name``."""
    if not cls.name or cls.name in MODELS:
        raise ValueError(f"model name {cls.name!r} empty or registered twice")
    MODELS[cls.name] = cls()
    return cls


def get_model(name: str) -> Model:
    """Registered model by name.

    The closures are imported first and the solvers (scikit-fem, gmsh, py-pde) only when
    the name is not a closure, so a closure starts without loading them.

    Parameters
    ----------
    name
        A model name, as ``wetcontact models`` lists them (e.g. ``"meniscus"``).

    Returns
    -------
    Model
        The registered instance (call ``.force(scene)``).

    Raises
    ------
    InputError
        An unknown name; the message lists the registered ones.
    """
    if not isinstance(name, str):
        raise InputError(f"model = {short_repr(name)}; allowed: a model name (a string), one "
                         "of " + ", ".join(sorted(load_all())))
    if name not in MODELS:
        import importlib

        importlib.import_module("wetcontact.reduced_models")
    if name not in MODELS:
        load_all()
    if name not in MODELS:
        raise InputError(f"model = {name!r}; allowed: " + ", ".join(sorted(MODELS)))
    return MODELS[name]


def load_all() -> dict[str, Model]:
    """Import every module that registers models (closures and the solvers present)."""
    import importlib

    for mod in ("wetcontact.reduced_models", "wetcontact.solver"):
        importlib.import_module(mod)
    return MODELS


_PROVENANCE: dict[str, Any] = {}


def provenance() -> dict[str, Any]:
    """Package version, git commit (when available), library versions, Python, host."""
    if not _PROVENANCE:
        import platform
        import subprocess
        from importlib import metadata
        from pathlib import Path

        def ver(dist: str) -> str:
            try:
                return metadata.version(dist)
            except metadata.PackageNotFoundError:
                return "not installed"

        commit = "unknown"
        try:
            here = Path(__file__).resolve().parent
            out = subprocess.run(["git", "rev-parse", "HEAD"], cwd=here, capture_output=True,
                                 text=True, timeout=5, check=False)
            if out.returncode == 0:
                commit = out.stdout.strip()
        except (OSError, subprocess.SubprocessError):
            pass
        _PROVENANCE.update(
            wetcontact=ver("wetcontact"), git_commit=commit, python=platform.python_version(),
            numpy=ver("numpy"), scipy=ver("scipy"), scikit_fem=ver("scikit-fem"),
            py_pde=ver("py-pde"), gmsh=ver("gmsh"), meshio=ver("meshio"), h5py=ver("h5py"),
        )
    return dict(_PROVENANCE)


def observed_order(h: Any, err: Any) -> float:
    """Observed convergence order: slope of ``log|err|`` against ``log h`` (least squares).

    Parameters
    ----------
    h
        Mesh sizes (or 1/N), at least two, positive.
    err
        Errors at those sizes, non-zero.
    """
    h = np.asarray(h, dtype=float)
    err = np.abs(np.asarray(err, dtype=float))
    if h.size < 2 or h.shape != err.shape or np.any(h <= 0) or np.any(err == 0):
        raise ValueError("observed_order needs >= 2 positive sizes and non-zero errors")
    return float(np.polyfit(np.log(h), np.log(err), 1)[0])


def closure_curve(scene: Scene, model: str, viscous: np.ndarray | None = None,
                  capillary: np.ndarray | None = None, error_estimate: np.ndarray | None = None,
                  outside: str = "", **extras: np.ndarray) -> ForceCurve:
    """Assemble a :class:`ForceCurve` for a closed-form model; ``outside``, if not empty,
    says why the scene lies outside the closure's stated validity (diagnostics
    ``outside_stated_validity``, which ``wetcontact solve`` prints as a warning)."""
    return ForceCurve(case=scene.name, model=model, gap=scene.gap_array,
                      force_viscous=viscous, force_capillary=capillary, extras=extras,
                      error_estimate=error_estimate,
                      diagnostics={"outside_stated_validity": outside} if outside else {})
