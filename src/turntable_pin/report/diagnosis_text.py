"""The diagnosis in words: the text rendering of the diagnosis JSON (``Diagnosis.to_dict()``), of
every family of data (orientation measurements, calibration runs).

Text, JSON and HTML are three views of one result: this module reads only the dictionary.
:func:`headline` is the one-line verdict both reports open with, :func:`verdict_lines` the part
the HTML shows in its verdict box, :func:`family_lines` what a family's own data add (a run's
other side, coefficients and table). A headline effect is a *partial explanation* when the model
with every accepted effect is still unexplained (chi2 test failed, or structure remains).
"""

from __future__ import annotations

from ..core.words import Command, argument, command
from ..stats.diagnosis_engine import DATA_PLACEHOLDER
from ..stats.model_selection import acceptance_rule

__all__ = [
    "DATA_PLACEHOLDER",
    "coefficient_lines",
    "decision_rule_words",
    "diagnosis_lines",
    "family_lines",
    "fit_command",
    "header_lines",
    "headline",
    "other_side_lines",
    "table_from_run_lines",
    "verdict_lines",
]


def _number(value, fmt: str = "#.3g") -> str:
    return "-" if value is None else format(value, fmt)


def _rms_key(summary: dict) -> str:
    return next(k for k in summary if k.startswith("rms_"))


_FORMAT = {"arcsec": ".3f", "dph": ".3g"}
"""How an rms is printed in each observation unit (arc seconds to 0.001; deg/h to 3 digits)."""


_SIDE_WORDS = {
    "table": "the table (its error reaches the outputs through the payload's attitude, eqs. 8-13)",
    "instrument": "the instrument (the GyroWheel itself, not the table)",
    "both": "the table and the instrument (the effects named are on both sides)",
}
"""The verdict's side in words (calibration runs: ``verdict.side``)."""


def _unit(d: dict) -> str:
    """The observations' unit of a diagnosis dict (``arcsec``, ``dph``)."""
    return _rms_key(d["base"])[len("rms_") :]


def _structure_words(structure: list[dict]) -> str:
    """The first remaining term (and how many more)."""
    first = structure[0]
    more = f" and {len(structure) - 1} more" if len(structure) > 1 else ""
    return f"{first['term']} ({first['amplitude']:.3g} {first['unit']}){more}"


def _still_unexplained(d: dict) -> str:
    """Why the best model is still unexplained, in a few words (empty when it is not)."""
    verdict = d["verdict"]
    structure = verdict["remaining_structure"]
    if structure:
        return f"structure remains: {_structure_words(structure)}"
    if verdict["fails_fit_test"]:
        return (
            f"the best model still fails the chi2 test (chi2_reduced "
            f"{_number(d['best']['chi2_reduced'], '.2f')})"
        )
    return ""


def _short(names: list[str]) -> str:
    """Parameter names without their effect's prefix (``c1, s1``)."""
    return ", ".join(n.rsplit(".", 1)[-1] for n in names)


def _parameter_words(entry: dict, base: str = "the base errors") -> str:
    """``c1 = -57.3 +- 37.4 arcsec (correlation with the base errors 0.91)``."""
    name = entry["name"].rsplit(".", 1)[-1]
    if entry["std"] is None:
        return f"{name} not seen on its own (absorbed into the model's errors on these data)"
    mark = "" if entry["determined"] else ", not determined"
    return (
        f"{name} = {entry['value']:.3g} +- {entry['std']:.2g} {entry['unit']} (correlation "
        f"with {base} {entry['correlation']:.2f}{mark})"
    )


def headline(d: dict) -> str:
    """The verdict in one line, from ``Diagnosis.to_dict()``.

    One of: ``Missing effect: E -- rms a -> b <unit>, chi2_reduced c -> d``; ``Partial
    explanation: E -- ...; still unexplained: why``; ``Unexplained structure: term (no catalogued
    effect) -- ...``; ``Unexplained misfit: ...``; ``The base model fits to the noise -- ...``.
    """
    verdict = d["verdict"]
    if verdict.get("doubt"):
        return f"Check the table: {verdict['doubt']} -- {_verdict_headline(d)}"
    return _verdict_headline(d)


def _verdict_headline(d: dict) -> str:
    verdict = d["verdict"]
    base, best = d["base"], d["best"]
    key = _rms_key(base)
    unit = key[len("rms_") :]
    if d["steps"]:
        effects = verdict["missing_effects"]
        also = verdict["also_significant"]
        change = (
            f"rms {_number(base[key])} -> {_number(best[key])} {unit}, chi2_reduced "
            f"{_number(base['chi2_reduced'])} -> {_number(best['chi2_reduced'])}"
        )
        loose = verdict.get("named_undetermined", {})
        sides = verdict.get("sides", {})
        named = " + ".join(
            e
            + (f" [{sides[e]}]" if e in sides else "")
            + (f" (parameters not determined: {_short(loose[e])})" if e in loose else "")
            for e in effects
        ) + (f" (also significant: {', '.join(also)})" if also else "")
        if verdict["unexplained"]:
            return f"Partial explanation: {named} -- {change}; still unexplained: " + (
                _still_unexplained(d)
            )
        label = "Missing effects" if len(effects) > 1 else "Missing effect"
        return f"{label}: {named} -- {change}"
    level = f"rms {_number(base[key])} {unit}, chi2_reduced {_number(base['chi2_reduced'])}"
    structure = verdict["remaining_structure"]
    if structure:
        return (
            f"Unexplained structure: {_structure_words(structure)} (no catalogued effect) "
            f"-- {level}"
        )
    if verdict["fails_fit_test"]:
        return (
            f"Unexplained misfit: no catalogued effect and no harmonic shape explains it -- "
            f"{level} (is the stated sigma too small?)"
        )
    return f"The base model fits to the noise -- {level}"


def decision_rule_words(d: dict | None = None) -> str:
    """The decision rule as every output says it (``diagnose --help``, the text, the HTML page):
    ``an effect is accepted when <acceptance_rule()>``, and with a result ``d`` its first
    round's threshold (``, here -10.4``)."""
    words = f"an effect is accepted when {acceptance_rule()}"
    threshold = (d or {}).get("decision_rule", {}).get("threshold")
    return words if threshold is None else f"{words}, here {threshold:.1f}"


def header_lines(d: dict) -> list[str]:
    """The data, the base fit and the table of candidates."""
    lines = []
    unit = _unit(d)
    sig = (
        f"from the sigma_{unit} column"
        if d["sigma_source"] == "column"
        else f"estimated from the best fit: {d[f'sigma_{unit}']:.3g} {unit}"
    )
    what = "outputs" if unit == "dph" else "angles"
    lines.append(f"{d['n_positions']} positions, {d['n_observations']} {what}; noise {sig}")
    b = d["base"]
    lines.append(
        f"base model: rms {b[f'rms_{unit}']:{_FORMAT[unit]}} {unit}, chi2_reduced "
        f"{b['chi2_reduced']:.3f}, {b['n_params']} parameters of rank {b['rank']}"
        + (f", p-value {b['p_value']:.3g}" if b["p_value"] is not None else "")
    )
    lines += [f"warning: {text}" for text in d.get("warnings", [])]
    lines.append(f"candidates (best first; {decision_rule_words(d)}):")
    first = d["steps"][0]["added"] if d["steps"] else None
    for c in d["candidates"]:
        if not c["testable"]:
            lines.append(f"  {c['effect']:26s} not testable: {c['reason']}")
            continue
        alt = f"  same as: {', '.join(c['alternatives'])}" if c["alternatives"] else ""
        later = c.get("delta_bic_after_first")
        accepted = c.get("in_best_model", c["significant"])
        if c["significant"] and not accepted:
            alt += "  (significant alone" + (
                f"; on top of {first}: {later:+.1f})" if later is not None else ")"
            )
        if c.get("determined") is False:
            alt += "  parameters not determined"
        if c.get("implausible"):
            alt += "  implausible"
        lines.append(
            f"  {c['effect']:26s} delta_bic {c['delta_bic']:10.1f}  rms "
            f"{c[f'rms_{unit}']:{_FORMAT[unit]}}  chi2_red {c['chi2_reduced']:.3f}"
            f"{'  *' if accepted else ''}{alt}"
        )
    lines.append("  (* in the final model)")
    return lines


def verdict_lines(d: dict, data: str = DATA_PLACEHOLDER) -> list[str]:
    """The steps of the forward selection, the missing effect and its rivals, whether anything
    remains (for each remaining term, the ``fit`` command on the file ``data`` that adds it) and
    the outliers left out."""
    return [*_effect_lines(d), *_rival_lines(d), *_unexplained_lines(d, data), *_outlier_lines(d)]


def _effect_lines(d: dict) -> list[str]:
    """Each step, the effect named (its side, why, how to confirm it, its parameters and
    whether the data determine them), or none."""
    verdict = d["verdict"]
    if not d["steps"]:
        return ["missing effect: none (no catalogued effect improves the base fit)"]
    lines = []
    for i, s in enumerate(d["steps"], 1):
        unit = _unit(d)
        lines.append(
            f"step {i}: add {s['added']} (delta_bic {s['delta_bic']:.1f}) -> rms "
            f"{s[f'rms_{unit}']:{_FORMAT[unit]}} {unit}, chi2_reduced "
            f"{s['chi2_reduced']:.3f}"
        )
    story = verdict["effect_story"]
    if verdict["unexplained"]:
        lines.append(
            f"partial explanation: {verdict['missing_effect']} ({story['title']}); "
            f"still unexplained: {_still_unexplained(d)}"
        )
    else:
        lines.append(f"missing effect: {verdict['missing_effect']} ({story['title']})")
    side = verdict.get("side")
    if side:
        lines.append(f"  side: {_SIDE_WORDS.get(side, side)}")
    lines.append(f"  why: {story['explanation']}")
    lines.append(f"  confirm on the machine: {story['confirm']}")
    base = d.get("base_label", "the base errors")
    for name, entries in verdict.get("named_parameters", {}).items():
        if entries:
            words = "; ".join(_parameter_words(e, base) for e in entries)
            lines.append(f"  {name} parameters: {words}")
    for name, loose in verdict.get("named_undetermined", {}).items():
        lines.append(
            f"  caution: {_short(loose)} of {name} are not determined (traded off against "
            "the model's other parameters, correlation > 0.95, or none reaches 3 sigma): the "
            "data support only the part of it they do determine; "
            "read it as the shape it adds, not as these values"
        )
    return lines


def _rival_lines(d: dict) -> list[str]:
    """The effects besides the one named: also significant, as good (with what separates them),
    significant but not determined, not needed beside the structure, absorbed by the base."""
    verdict = d["verdict"]
    lines = []
    if verdict["also_significant"]:
        lines.append(
            "also significant on top of it: "
            + ", ".join(verdict["also_significant"])
            + f" ({argument('until_explained')} names every step)"
        )
    commands = verdict.get("separation_commands", {})
    for name in verdict.get("alternatives", []):
        if name in verdict["separations"]:
            lines.append(f"  alternative {name}: {verdict['separations'][name]}")
            lines += _settle(commands, name)
    kept = (
        "the effect named, whose parameters are determined, is kept"
        if d["steps"] and not verdict.get("named_undetermined")
        else "no effect is preferred for it"
    )
    for entry in verdict.get("not_named_undetermined", []):
        lines.append(
            f"not named: {entry['effect']} (delta_bic {entry['delta_bic']:.1f}, significant "
            f"alone), but the data do not determine its {_short(entry['undetermined'])} "
            f"(correlation > 0.95 with the model's other parameters, or none reaches 3 sigma); "
            f"{kept}"
        )
        if entry["effect"] in verdict["separations"]:
            lines.append(f"  {entry['effect']}: {verdict['separations'][entry['effect']]}")
            lines += _settle(commands, entry["effect"])
    lines += _set_lines(verdict)
    for entry in verdict.get("implausible", []):
        score = entry["delta_bic"]
        alone = f" (delta_bic {score:.1f}, significant alone)" if score is not None else ""
        lines.append(
            f"not named: {entry['effect']}{alone} is implausible: to accept it one would have to "
            f"believe in {entry['belief']}"
        )
    for entry in verdict.get("unneeded_given_structure", []):
        lines.append(
            f"not named: {entry['effect']} was significant on its own, but the best description "
            f"of the data does not need it (removing it changes BIC by "
            f"{entry['bic_cost_of_removing']:+.1f}; an effect must earn at least 6)"
        )
    for name in verdict["indistinguishable_from_base"]:
        lines.append(
            f"note: {name} cannot be told apart from the base errors on these data (if "
            "present, it is absorbed into them; see its candidate entry)"
        )
    return lines


def _set_lines(verdict: dict) -> list[str]:
    """Each many-parameter effect compared with a set of simpler ones, and how the set fared."""
    lines = []
    for entry in verdict.get("simpler_sets", []):
        if not entry["simpler_set"]:
            continue
        effect = (
            f"{entry['effect']} ({entry['added_rank']} parameters, delta_bic "
            f"{entry['delta_bic']:.1f})"
        )
        names = " + ".join(entry["simpler_set"])
        numbers = f"({entry['set_added_rank']} parameters, delta_bic {entry['set_delta_bic']:.1f})"
        if entry["set_named"]:
            lines.append(
                f"parsimony at step {entry['step']}: the simpler set {names} {numbers} has a "
                f"lower BIC than {effect}, so the set is taken instead"
                + _set_afterwards(
                    entry, [*verdict["missing_effects"], *verdict["also_significant"]]
                )
            )
        else:
            lines.append(
                f"parsimony at step {entry['step']}: {effect} is kept; the best simpler set, "
                f"{names} {numbers}, " + _set_fared(entry["set_delta_bic"], entry["delta_bic"])
            )
    return lines


def _set_afterwards(entry: dict, named: list[str]) -> str:
    """What later steps made of a set taken instead of a many-parameter effect: a member the
    final model does not need, or the effect added after all (the verdict names the final model,
    so its parsimony line must not claim more)."""
    dropped = [m for m in entry["simpler_set"] if m not in named]
    words = []
    if dropped:
        words.append(f"{' and '.join(dropped)} left out at the end (not needed by the final model)")
    if entry["effect"] in named:
        words.append(f"{entry['effect']} still added at a later step")
    return f"; afterwards {'; '.join(words)}" if words else ""


def _set_fared(set_delta_bic: float, delta_bic: float) -> str:
    """How a simpler set that was not named fared against the effect kept."""
    if abs(set_delta_bic - delta_bic) <= 1e-6 * max(1.0, abs(delta_bic)):
        return "fits exactly as well: the same signal, which the one effect names"
    if set_delta_bic > delta_bic:
        return "does not fit as well"
    return "fits as well only with an implausible amplitude"


def _unexplained_lines(d: dict, data: str) -> list[str]:
    """Whether the best model leaves anything unexplained, and the command that fits it."""
    verdict = d["verdict"]
    lines = []
    if verdict["unexplained"]:
        why = []
        structure = verdict["remaining_structure"]
        if verdict["fails_fit_test"]:
            why.append("the best model fails the chi2 test")
        if structure:
            why.append(
                "structure remains: "
                + "; ".join(
                    f"{t['description']} ({t['amplitude']:.3g} {t['unit']}, "
                    f"delta_bic {t['delta_bic']:.0f})"
                    for t in structure
                )
            )
        elif verdict["fails_fit_test"]:
            why.append(
                "without harmonic structure: the stated sigma may be too small or the "
                "missing effect is not a harmonic one"
            )
        lines.append("unexplained: yes, " + "; ".join(why))
        specs = [t["effect_spec"] for t in structure if t.get("effect_spec")]
        if specs:
            effects = [*d.get("best", {}).get("effects", []), *specs]
            lines.append(
                "  fit with what remains: "
                + str(fit_command(data, effects, d.get("refit_command", "fit")))
            )
    else:
        lines.append("unexplained: no (the residuals are consistent with the noise)")
    return lines


def _outlier_lines(d: dict) -> list[str]:
    """The observations left out as gross outliers (row, column, residual), and the rule."""
    outliers = d.get("outliers", [])
    if not outliers:
        return []
    shown = ", ".join(
        f"row {o['row']} {_record_column(o)} ({o['residual_sigma']:+.1f} sigma)"
        for o in outliers[:10]
    )
    more = f" and {len(outliers) - 10} more" if len(outliers) > 10 else ""
    return [
        f"outliers left out of every fit ({len(outliers)}): {shown}{more}; the rule: "
        f"{d.get('outlier_rule')}; {argument('outliers=False')} keeps them"
    ]


def _record_column(record: dict) -> str:
    """The observation column an outlier record names (under its family's key: ``angle``,
    ``output``)."""
    return next(v for k, v in record.items() if k not in ("row", "residual_sigma"))


def _settle(commands: dict, name: str) -> list[str]:
    """The line with the ``design`` command that settles the separation of ``name`` (none when
    the JSON has no command for it)."""
    if name not in commands:
        return []
    return [f"    to settle it, design the next positions: {commands[name]}"]


def fit_command(data: str, specs: list[str], name: str = "fit") -> Command:
    """The ``fit`` command (``calibrate`` for a run) that adds the inline terms ``specs``."""
    return command(name, data, effects=",".join(specs))


def other_side_lines(d: dict) -> list[str]:
    """The effects of the other side (table vs instrument) that move the outputs like the one
    named, on the run's positions: the confounded explanations, and what would separate them
    (none when the result has no other side)."""
    verdict = d["verdict"]
    if "other_side" not in verdict or not verdict["missing_effect"]:
        return []
    rivals = verdict["other_side"]
    other = "instrument" if verdict["side"] == "table" else "table"
    if not rivals:
        return [
            f"the other side: no effect of the {other} moves the outputs like "
            f"{verdict['missing_effect']} on these positions"
        ]
    lines = [
        f"the other side: on these positions, {len(rivals)} effect(s) of the "
        f"{other} move the outputs like "
        f"{verdict['missing_effect']} (confounded: the run alone cannot say which side it is):"
    ]
    commands = verdict.get("separation_commands", {})
    for r in rivals:
        lines.append(f"  {r['effect']} (noise-free misfit chi2 {r['chi2_run']:.2g} here): "
                     f"{r['words']}")  # fmt: skip
        lines += _settle(commands, r["effect"])
    return lines


def coefficient_lines(d: dict) -> list[str]:
    """The calibrated coefficients of the best model, both axes (deg/h-based units); none when
    the result has none."""
    if "coefficients_dph" not in d:
        return []
    lines = ["coefficients of the final model (value +- std):"]
    for axis, terms in d["coefficients_dph"].items():
        for name, entry in terms.items():
            std = "-" if entry["std"] is None else f"{entry['std']:.3g}"
            lines.append(f"  D{axis}{name:3s} = {entry['value']:12.6f} +- {std} {entry['unit']}")
    return lines


def table_from_run_lines(d: dict) -> list[str]:
    """What a calibration run tells about the table's errors; none when the result has no
    ``table_from_run``."""
    if "table_from_run" not in d:
        return []
    t = d["table_from_run"]
    lines = [
        f"the table from the run: its {len(t['errors'])} errors add {t['rank_added']} "
        f"combination(s) the outputs determine (noise {t['sigma_dph']:.3g} deg/h):"
    ]
    lines += [f"  {c['name']} = {c['value']:.3g} +- {c['std']:.2g} {c['unit']}"
              for c in t["determined"]]  # fmt: skip
    absorbed = [f"{a['error']} ({a['correlation']:.2f})" for a in t["absorbed"]]
    if t["with_coefficients"]:
        lines.append("  determined only together with the instrument's coefficients: "
                     + "; ".join(c["name"] for c in t["with_coefficients"][:6]))  # fmt: skip
    if absorbed:
        lines.append(f"  mostly absorbed by the coefficients (correlation > "
                     f"{t['absorbed_above']:g}: the calibration takes them for instrument terms): "
                     + ", ".join(absorbed))  # fmt: skip
    if t["undetermined"]:
        lines.append("  not seen at all (only the sums above are): "
                     + "; ".join(t["undetermined"][:6]))  # fmt: skip
    return lines


def family_lines(d: dict) -> list[str]:
    """The lines of a family's own data, after the verdict: the other side, the coefficients
    and the table from the run (a calibration run's)."""
    return [*other_side_lines(d), *coefficient_lines(d), *table_from_run_lines(d)]


def diagnosis_lines(d: dict, data: str | None = None) -> list[str]:
    """The whole diagnosis in words: the headline, the header lines, the verdict lines (with the
    fit command for ``data``: default the result's ``source``, else :data:`DATA_PLACEHOLDER`) and
    the family's own lines."""
    data = data or d.get("source") or DATA_PLACEHOLDER
    return [headline(d), *header_lines(d), *verdict_lines(d, data), *family_lines(d)]
