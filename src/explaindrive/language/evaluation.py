"""Quantitative evaluation of LLM-1 (intents) and LLM-2/LLM-3 (decisions, explanations)."""

from __future__ import annotations

from typing import Any

import numpy as np
from sklearn.metrics import (
    accuracy_score,
    cohen_kappa_score,
    confusion_matrix,
    f1_score,
    precision_recall_fscore_support,
)

from explaindrive.commands import COMMAND_LABELS, Command
from explaindrive.language.explanation.datasets import LabelledRecord
from explaindrive.language.explanation.decision import ExplanationDecider
from explaindrive.language.explanation.explainer import Explainer, check_grounding, present_factors
from explaindrive.language.explanation.grounding import reply_problems
from explaindrive.language.explanation.hazards import Factor
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.language.intent.agreement import TwoReadings, trust_sweep
from explaindrive.language.intent.datasets import CommandExample
from explaindrive.language.intent.interpreter import (
    IntentInterpreter,
    IntentResult,
    is_template_compliant,
)

CONFUSION_LABELS: tuple[str, ...] = (*COMMAND_LABELS, "none")


def _percentiles(values: list[float]) -> dict[str, float]:
    if not values:
        return {"p50_ms": 0.0, "p95_ms": 0.0}
    arr = np.asarray(values) * 1000.0
    return {
        "p50_ms": round(float(np.percentile(arr, 50)), 3),
        "p95_ms": round(float(np.percentile(arr, 95)), 3),
    }


def intent_metrics(
    truth: list[str], pred: list[str], confirmations: list[str | None]
) -> dict[str, Any]:
    """Metrics of LLM-1 from labels (``fast|comfort|stop|none``) and predictions.

    The 3-class figures (accuracy, macro-F1, kappa, per class) use the rows whose true
    label is a command; a ``none`` prediction on such a row counts as an error. Template
    compliance is the share of those rows whose output is exactly the template question.
    ``none_rejection`` is the share of ``none`` rows left without a command. A file
    without command rows (or without ``none`` rows) gets ``None`` for the figures it
    cannot give.
    """
    idx = [i for i, t in enumerate(truth) if t != "none"]
    none_idx = [i for i, t in enumerate(truth) if t == "none"]
    out: dict[str, Any] = {
        "n": len(truth),
        "n_commands": len(idx),
        "n_none": len(none_idx),
        "none_rejection": round(float(np.mean([pred[i] == "none" for i in none_idx])), 4)
        if none_idx
        else None,
        "none_read_as_stop": sum(pred[i] == "stop" for i in none_idx),
        "confusion": {
            "labels": list(CONFUSION_LABELS),
            "matrix": confusion_matrix(truth, pred, labels=list(CONFUSION_LABELS)).tolist(),
        },
    }
    out.update(_command_metrics([truth[i] for i in idx], [pred[i] for i in idx]))
    out["template_compliance"] = (
        round(float(np.mean([is_template_compliant(confirmations[i]) for i in idx])), 4)
        if idx
        else None
    )
    return out


def _command_metrics(t3: list[str], p3: list[str]) -> dict[str, Any]:
    """Accuracy, macro-F1, kappa and per-class figures over the command rows."""
    labels = list(COMMAND_LABELS)
    if not t3:
        return {"accuracy": None, "macro_f1": None, "cohen_kappa": None, "per_class": {}}
    prec, rec, f1, sup = precision_recall_fscore_support(t3, p3, labels=labels, zero_division=0)
    return {
        "accuracy": round(float(accuracy_score(t3, p3)), 4),
        "macro_f1": round(
            float(f1_score(t3, p3, labels=labels, average="macro", zero_division=0)), 4
        ),
        "cohen_kappa": round(float(cohen_kappa_score(t3, p3)), 4) if len(set(t3)) > 1 else None,
        "per_class": {
            name: {
                "precision": round(float(prec[k]), 4),
                "recall": round(float(rec[k]), 4),
                "f1": round(float(f1[k]), 4),
                "support": int(sup[k]),
            }
            for k, name in enumerate(labels)
        },
    }


def evaluate_intents(interpreter: IntentInterpreter, rows: list[CommandExample]) -> dict[str, Any]:
    """Run ``interpreter`` over labelled requests; metrics plus every error and latency.

    ``replies`` counts what became of a remote model's replies: ``accepted`` (read and
    used), ``fallback`` (unreadable, an error or late: the embedded reading stood in),
    ``vetoed`` (read, but overruled by a sure embedded reading) and ``not_asked`` (the
    embedded STOP lane, or an empty line). ``by_kind`` gives [correct, total] per kind;
    ``negated_stops_read_as_stop`` counts the rows of kind ``negated_stop`` read as STOP.
    ``asked_stop`` counts, per label, the rows given no command whose reading the car asks
    about ("You want me to stop...?"), and ``stop_heard`` is the share of STOP rows read as
    STOP or asked about (the recall once the passenger's yes is counted).
    With a remote model, ``trust_sweep`` gives the figures each ``trust_embedded_from`` of
    :data:`~explaindrive.language.intent.agreement.TRUST_GRID` would have given on the same
    replies (:func:`~explaindrive.language.intent.agreement.trust_sweep`).
    """
    results = [interpreter.interpret(row.text) for row in rows]
    preds = [r.intent.label if r.intent is not None else "none" for r in results]
    both = [
        TwoReadings(row.label, r.readings[0], r.readings[1], r.readings[2], True)
        if r.readings is not None
        # the embedded reading stood alone (a fallback, the STOP lane, no remote)
        else TwoReadings(row.label, r.intent, 1.0, None, False)
        for row, r in zip(rows, results, strict=True)
    ]
    replies = _reply_counts(results)
    out = intent_metrics([r.label for r in rows], preds, [r.confirmation for r in results])
    out.update(
        errors=_errors(rows, results, preds),
        fallbacks=replies["fallback"],
        replies=replies,
        by_kind=_by_kind(rows, preds),
        negated_stops_read_as_stop=sum(
            p == "stop" for p, row in zip(preds, rows, strict=True) if row.kind == "negated_stop"
        ),
        latency=_percentiles([r.latency_s for r in results]),
        **_asked(rows, results),
    )
    if any(x.readable for x in both):
        out["trust_sweep"] = trust_sweep(both)
    return out


def _asked(rows: list[CommandExample], results: list[IntentResult]) -> dict[str, Any]:
    """``asked_stop`` (per label) and ``stop_heard`` (see :func:`evaluate_intents`)."""
    asked: dict[str, int] = {}
    for row, r in zip(rows, results, strict=True):
        if r.intent is None and r.ask is Command.STOP:
            asked[row.label] = asked.get(row.label, 0) + 1
    stops = [r for row, r in zip(rows, results, strict=True) if row.label == "stop"]
    heard = sum(r.intent is Command.STOP or r.ask is Command.STOP for r in stops)
    return {
        "asked_stop": asked,
        "stop_heard": round(heard / len(stops), 4) if stops else None,
    }


def _reply_counts(results: list[IntentResult]) -> dict[str, int]:
    """What became of a remote model's replies (see :func:`evaluate_intents`)."""
    replies = {"accepted": 0, "fallback": 0, "vetoed": 0, "not_asked": 0}
    for r in results:
        if r.fallback:
            replies["fallback"] += 1
        elif r.overruled:
            replies["vetoed"] += 1
        elif r.raw_reply is not None:
            replies["accepted"] += 1
        else:
            replies["not_asked"] += 1
    return replies


def _by_kind(rows: list[CommandExample], preds: list[str]) -> dict[str, list[int]]:
    """[correct, total] per kind of request (``-`` for rows without one)."""
    by_kind: dict[str, list[int]] = {}
    for row, label in zip(rows, preds, strict=True):
        tally = by_kind.setdefault(row.kind or "-", [0, 0])
        tally[0] += label == row.label
        tally[1] += 1
    return by_kind


def _errors(
    rows: list[CommandExample], results: list[IntentResult], preds: list[str]
) -> list[dict[str, str | None]]:
    """Every row read wrong, with the remote reply where there was one."""
    errors = []
    for row, r, label in zip(rows, results, preds, strict=True):
        if label == row.label:
            continue
        error: dict[str, str | None] = {
            "text": row.text,
            "label": row.label,
            "pred": label,
            "kind": row.kind,
            "reading": r.reading,
        }
        if r.raw_reply is not None:
            error.update(rule=r.rule, raw_reply=r.raw_reply)
        errors.append(error)
    return errors


def evaluate_everyday(interpreter: IntentInterpreter, texts: list[str]) -> dict[str, Any]:
    """LLM-1 on everyday lines that ask for no command (the external check).

    Returns:
        ``n``; ``left_without_command`` (share); ``left_alone`` (share given no command
        and not asked about either); ``commands`` (count per command given);
        ``asked_stop`` (count of lines the car asks whether to stop); ``readings`` (count
        per reading); ``given`` (every line given a command, with it); ``asked`` (every
        line asked about).
    """
    results = [interpreter.interpret(t) for t in texts]
    commands = {c: 0 for c in COMMAND_LABELS}
    readings: dict[str, int] = {}
    given = []
    asked = []
    for text, r in zip(texts, results, strict=True):
        readings[r.reading or "-"] = readings.get(r.reading or "-", 0) + 1
        if r.intent is not None:
            commands[r.intent.label] += 1
            given.append({"text": text, "command": r.intent.label})
        elif r.ask is not None:
            asked.append({"text": text, "command": r.ask.label})
    n = len(texts)
    return {
        "n": n,
        "left_without_command": round(1.0 - len(given) / n, 4) if n else None,
        "left_alone": round(1.0 - (len(given) + len(asked)) / n, 4) if n else None,
        "commands": commands,
        "asked_stop": len(asked),
        "readings": readings,
        "given": given,
        "asked": asked,
        "latency": _percentiles([r.latency_s for r in results]),
    }


def evaluate_decisions(
    decider: ExplanationDecider, explainer: Explainer, rows: list[LabelledRecord]
) -> dict[str, Any]:
    """Trigger accuracy/precision/recall/F1, factor accuracy, and checked explanations.

    Factor accuracy is over the labelled ``explain`` rows that the decider also chose to
    explain; ``factor_accuracy_multi`` over those whose state holds two or more objects
    (light, crossing, leader) within the cut-off. Every explanation is checked: it names
    the labelled factor and no factor absent from the state (``grounded_share``), and it
    passes :func:`~explaindrive.language.explanation.grounding.reply_problems` — the light's colour,
    distances and speeds, and wording true of the action and speed (``truthful_share``).
    """
    truth: list[bool] = []
    pred: list[bool] = []
    factor_hits: list[tuple[bool, bool]] = []  # (hit, multi-factor)
    texts: list[dict[str, Any]] = []
    lat_decide: list[float] = []
    lat_explain: list[float] = []
    fallbacks = vetoed = 0
    for row in rows:
        rec = row.record()
        d = decider.decide(rec)
        truth.append(row.explain)
        pred.append(d.explain)
        lat_decide.append(d.latency_s)
        fallbacks += d.fallback
        vetoed += d.vetoed
        if d.explain:
            e = explainer.explain(rec, d.factor)
            lat_explain.append(e.latency_s)
            texts.append(_checked_text(row, rec, d.factor, e.text))
            if row.explain:
                factor_hits.append((d.factor == row.factor, _objects(rec) >= 2))
    prec, rec_, f1, _ = precision_recall_fscore_support(
        truth, pred, average="binary", pos_label=True, zero_division=0
    )
    labelled = [t for t in texts if t["label_factor"] is not None]
    multi = [hit for hit, is_multi in factor_hits if is_multi]
    return {
        "n": len(rows),
        "n_explain": int(sum(truth)),
        "accuracy": round(float(accuracy_score(truth, pred)), 4),
        "precision": round(float(prec), 4),
        "recall": round(float(rec_), 4),
        "f1": round(float(f1), 4),
        "factor_accuracy": _share([hit for hit, _ in factor_hits]),
        "factor_accuracy_multi": _share(multi),
        "n_multi": len(multi),
        "grounded_share": _share([t["grounded"] for t in labelled]),
        "truthful_share": _share([not t["problems"] for t in texts]),
        "fallbacks": fallbacks,
        "vetoed": vetoed,
        "latency": {"decide": _percentiles(lat_decide), "explain": _percentiles(lat_explain)},
        "explanations": texts,
    }


def _share(flags: list[bool]) -> float | None:
    return round(float(np.mean(flags)), 4) if flags else None


def _objects(rec: StateRecord) -> int:
    """Objects (light, crossing, leader) in the state within the cut-off."""
    return len(present_factors(rec.nearby()) - {Factor.SPEED_LIMIT})


def _checked_text(
    row: LabelledRecord, rec: StateRecord, factor: Factor | None, text: str
) -> dict[str, Any]:
    """One explanation with the results of the grounding and truth checks."""
    g = check_grounding(text, row.factor, rec)
    return {
        "id": row.id,
        "factor": factor.value if factor else None,
        "label_factor": row.factor.value if row.factor else None,
        "text": text,
        "names_factor": g.names_factor,
        "absent_factors": [f.value for f in g.absent],
        "grounded": g.ok,
        "problems": reply_problems(text, rec, factor),
    }
