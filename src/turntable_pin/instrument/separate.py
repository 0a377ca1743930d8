"""Positions that tell two explanations of a calibration run apart.

When effect B moves the outputs like effect A on the run's positions (a table error and the
instrument's tilt), where to calibrate next? Each effect at the amplitude the run fits it with:
if A is true, fitting the coefficients and B to A's prediction leaves ``lambda_AB = || (I - P_B)
J_A a ||^2 / sigma^2`` over the run and the new positions (``lambda_BA`` the other way). The
design maximises the smaller (T-optimal, ``stats.discrimination.t_optimal_exchange``) over seeded
candidates within the joints' limits; ``SEPARATION_CHI2`` (25: five sigma) tells them apart
clearly. When B reproduces A at every candidate, the result says so with the effects' independent
tests. Effects needing ``time_s`` or another column are refused: positions do not decide them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..calibration.positions import PositionSet, position_inputs
from ..calibration.run import CalibrationRun
from ..core.exceptions import InputError
from ..core.sizes import check_positions_count
from ..core.words import argument
from ..stats.diagnosis_engine import SEPARATION_CHI2
from ..stats.discrimination import SAME_RTOL, Direction, t_optimal_exchange
from .diagnosis import RunFamily
from .model import RunModel, run_context

__all__ = ["RunSeparation", "design_run_separation"]


@dataclass(frozen=True)
class RunSeparation:
    """The positions that tell two run effects ``(A, B)`` apart, or why none do.

    Attributes:
        positions_deg: (n, J) the chosen positions of the ``joint_names``, degrees (empty when
            none separate them).
        misfit_run: ``(lambda_AB, lambda_BA)`` on the run alone (chi2); misfit_design: with the
            chosen positions added.
        separable: whether some positions tell them apart; words: the conclusion.
        n_candidates, seed: the candidates chosen from and their seed.
        noise_dph: the output noise the misfits are in units of.
        implausible: ``{effect: what one would have to believe}`` of each effect whose amplitude
            fitted on the run is beyond the physical scale of its kind (``docs/plausibility.md``):
            no positions are planned then.
    """

    effects: tuple[str, str]
    joint_names: tuple[str, ...]
    positions_deg: np.ndarray
    misfit_run: tuple[float, float]
    misfit_design: tuple[float, float]
    separable: bool
    words: str
    n_candidates: int
    seed: int
    noise_dph: float
    implausible: dict[str, str] = field(default_factory=dict)

    def columns(self) -> dict[str, np.ndarray]:
        """The positions as run columns ``phiK_deg`` (what a simulated run's positions read)."""
        return {f"phi{k + 1}_deg": self.positions_deg[:, k] for k in range(len(self.joint_names))}

    def to_dict(self) -> dict:
        """The result as a JSON-ready dict."""
        return {
            "effects": list(self.effects),
            "separable": self.separable,
            "words": self.words,
            "misfit_run": list(self.misfit_run),
            "misfit_design": list(self.misfit_design),
            "separation_chi2": SEPARATION_CHI2,
            "noise_dph": self.noise_dph,
            "implausible": dict(self.implausible),
            "n_candidates": self.n_candidates,
            "seed": self.seed,
            "positions": [dict(zip(self.columns(), map(float, row), strict=True))
                          for row in self.positions_deg],
        }  # fmt: skip

    def report(self) -> str:
        """The result in words, with the positions."""
        a, b = self.effects
        lines = [
            f"separate {a} from {b} (calibration run; noise {self.noise_dph:.3g} deg/h, "
            f"{self.n_candidates} candidates, seed {self.seed})",
            f"on the run alone: misfit {self.misfit_run[0]:.3g} ({a} true, {b} fitted), "
            f"{self.misfit_run[1]:.3g} ({b} true, {a} fitted); {SEPARATION_CHI2:g} separates "
            "clearly",
            self.words,
        ]
        if self.separable:
            lines.append(" ".join(f"{k:>10s}" for k in self.columns()))
            lines += [" ".join(f"{v:10.3f}" for v in row) for row in self.positions_deg]
        return "\n".join(lines)


def _whitened(context, rival, true_effect, params, sigma):
    """At ``context``, over ``sigma``: the columns (N, 2, q) of the coefficients and ``rival``,
    and the signal (N, 2) of ``true_effect`` at its ``params``."""
    model = RunModel(context, [true_effect])
    n_base = model.n_params - len(params)
    signal = np.einsum("ncp,p->nc", model.columns[:, :, n_base:], params) / sigma
    return RunModel(context, [rival]).columns / sigma, signal


def design_run_separation(
    run, names: tuple[str, str], candidates_rad: np.ndarray, n: int, *, seed: int = 0,
    catalogue=None,
) -> RunSeparation:  # fmt: skip
    """The ``n`` positions among ``candidates_rad`` (C, J) that best tell the run effects
    ``names`` apart (module docstring), each at the amplitude ``run`` fits it with.

    Raises:
        InputError: ``n`` not from 1 to C (checked first: each candidate is chosen at most once);
            an unknown effect, the same one twice, one the run does not see.
    """
    n = check_positions_count(n, len(candidates_rad), "n")
    family = RunFamily(run, catalogue)
    a, b = _pair(family, names)
    # the noise of one output: the stated one, else the run's estimate under the base model
    if run.sigma_dph is not None:
        sigma = float(np.median(run.sigma_dph))
    else:
        sigma = float(np.sqrt(family.fit([]).result.noise_variance))
    positions = PositionSet(candidates_rad, table=run.table, name="candidates")
    candidates = CalibrationRun(position_inputs(positions, run.inputs.latitude_rad),
                                np.zeros((len(positions), 2)))  # fmt: skip
    context = run_context(candidates, family.context.coefficients)

    def direction(true_effect, rival):
        p = family.fit([true_effect]).result.params[-len(true_effect.parameters(run)) :]
        fitted, signal = _whitened(context, rival, true_effect, p, sigma)
        fixed, fixed_signal = _whitened(family.context, rival, true_effect, p, sigma)
        q = fitted.shape[-1]
        return Direction(fitted, signal, fixed.reshape(-1, q), fixed_signal.reshape(-1))

    implausible = {
        e.name: belief
        for e in (a, b)
        if (belief := family.implausibility(e, family.fit([e]))) is not None
    }
    if implausible:
        none = np.zeros((0, candidates_rad.shape[1]))
        words = "; ".join(
            f"not planned: {name}'s amplitude fitted on the run is implausible; to accept it one "
            f"would have to believe in {belief}"
            for name, belief in implausible.items()
        )
        return RunSeparation((a.name, b.name), tuple(run.table.joint_names), none, (0.0, 0.0),
                             (0.0, 0.0), False, words, len(positions), int(seed), sigma,
                             implausible)  # fmt: skip
    directions = [direction(a, b), direction(b, a)]
    before = tuple(float(d.misfit(np.zeros(0, int))) for d in directions)
    exchange = t_optimal_exchange(directions, n, seed=seed)
    after = tuple(float(v) for v in exchange.noncentralities)
    scales = [float(np.sum(d.signal[exchange.chosen] ** 2)) for d in directions]
    same = [v <= SAME_RTOL * max(w, 1e-300) for v, w in zip(after, scales, strict=True)]
    chosen = np.degrees(candidates_rad[exchange.chosen])
    if any(same):
        chosen = np.zeros((0, candidates_rad.shape[1]))
    return RunSeparation(
        effects=(a.name, b.name),
        joint_names=tuple(run.table.joint_names),
        positions_deg=np.round(chosen, 6),
        misfit_run=before,
        misfit_design=after,
        separable=not any(same),
        words=_words(a, b, before, after, same, n),
        n_candidates=len(positions),
        seed=int(seed),
        noise_dph=sigma,
    )


def _pair(family: RunFamily, names: tuple[str, str]):
    """The two effects named (``table:`` may be left out), each one the run sees."""
    known = {e.name: e for e in family.catalogue}
    for name in names:
        if name not in known and f"table:{name}" not in known:
            raise InputError(f"unknown run effect '{name}'; known: {', '.join(known)}")
    a, b = (known.get(name) or known[f"table:{name}"] for name in names)
    if a is b:
        raise InputError(
            f"{argument('separate')} needs two different effects, got '{a.name}' twice"
        )
    for effect in (a, b):
        if effect.required_columns:
            raise InputError(
                f"effect '{effect.name}' depends on {', '.join(effect.required_columns)}, which "
                "a choice of positions cannot set: repeat positions late in the run (a drift), or "
                "calibrate at another temperature (a temperature coefficient), to tell it apart"
            )
    base_rank = family.fit([]).result.rank
    fits = [family.fit([a]), family.fit([b])]
    for effect, fit in zip((a, b), fits, strict=True):
        if fit.result.rank <= base_rank:
            raise InputError(
                f"the run does not see {effect.name}: on its positions it moves the outputs only "
                "like the 14 coefficients, so its amplitude cannot be fitted there; calibrate at "
                "more varied positions first (a grid), or design with the orientation effects"
            )
    return a, b


def _words(a, b, before, after, same, n: int) -> str:
    """The conclusion in a sentence: no positions separate them, one is a special case of the
    other, these positions do, or not yet."""
    both = f"For {a.name}: {a.confirm} For {b.name}: {b.confirm}"
    if all(same):
        return (
            f"no positions within the limits separate them: {b.name} reproduces {a.name} at "
            f"every candidate position (and the other way round); an independent test does. {both}"
        )
    if any(same):
        small, large = (b, a) if same[1] else (a, b)
        return (
            f"{small.name} is a special case of {large.name} at every position: when "
            f"{small.name} is true, {large.name} reproduces it and the diagnosis keeps the "
            f"simpler {small.name} (its rule makes the extra parameters pay); when {large.name} "
            f"is true, {small.name} leaves a misfit of {max(after):.3g} with these positions "
            f"({max(before):.3g} on the run alone). No positions make them more different; an "
            f"independent test does. {both}"
        )
    if min(after) >= SEPARATION_CHI2:
        already = (
            "the run alone already tells them apart (misfit at least "
            f"{min(before):.3g} both ways); "
            if min(before) >= SEPARATION_CHI2
            else ""
        )
        return (
            f"{already}these {n} positions, calibrated besides the run, leave a misfit of at "
            f"least {min(after):.3g} whichever is true: the diagnosis of the two runs together "
            "tells them apart"
        )
    return (
        f"these {n} positions raise the smaller misfit to {min(after):.3g}, still below "
        f"{SEPARATION_CHI2:g}: choose more positions ({argument('n')}) or repeat them"
    )
