"""When the remote model and the embedded interpreter read a line differently.

With the ``openai`` backend every line is read twice: by the embedded interpreter
(first, offline, with class probabilities) and by the remote model. The policy, one
rule per case, in the order they are tried:

1. ``stop-local``: the embedded reading is STOP. It is answered at once; the remote
   model is not asked (the STOP lane).
2. ``agree``: both readings are the same (a command, or not a driving request).
3. ``local-sure-none``: the embedded reading is "not a request" with probability at least
   ``sure_p`` (the config's ``openai.trust_embedded_from``, :data:`SURE_P` by default).
   A remote command, STOP included, does not turn it into a driving change.
4. ``local-sure``: the embedded reading is a command with probability at least
   ``sure_p``; it stands against a different remote command (STOP included) or a
   remote "not a request".
5. ``stop-remote``: the remote reading is STOP and the embedded reading is unsure: STOP
   (the passenger is still asked to confirm it).
6. ``remote-none``: the remote model says the line is not a driving request and the
   embedded reading is an unsure command: no command, the passenger is asked to
   rephrase.
7. ``remote``: otherwise (the embedded reading is unsure) the remote command is taken.

A STOP from the embedded reader always wins; a STOP from the remote reader wins unless
the embedded reader is sure of another reading (rules 3 and 4). A small model says STOP
for requests that are plainly something else (SmolLM2-135M did so for "My boss will have
my head if I'm late for this pitch.", which the embedded reader gives fast at 0.975);
the embedded STOP check already catches every STOP request of both test splits.

How far to trust a model is a property of the model: ``explaindrive score intents
--backend openai`` reports, from one pass over the data, the figures every ``sure_p`` of
:data:`TRUST_GRID` would give (:func:`trust_sweep`), so that it is chosen on data no model
was built on (the ``reserve`` split of ``commands_train.csv``). ``sure_p = 0`` leaves every
reading to the embedded interpreter: the model can then only agree.

Only a well-formed remote reply takes part; a malformed one, an error or a call past its
deadline leaves the embedded reading alone (a fallback, counted as such).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from explaindrive.commands import Command

SURE_P = 0.8  # the embedded reading's probability from which it is not overridden
TRUST_GRID: tuple[float, ...] = (0.0, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 1.0)
"""The values of ``sure_p`` that :func:`trust_sweep` scores."""


@dataclass(frozen=True, slots=True)
class Verdict:
    """The reading that counts and the rule that chose it.

    Attributes:
        intent: the command, or ``None`` (not a driving request).
        source: ``embedded``, ``openai`` or ``both`` (the readings agree).
        rule: the name of the policy's rule that decided (see the module docstring).
    """

    intent: Command | None
    source: str
    rule: str


def reconcile(
    local: Command | None,
    local_p: float,
    remote: Command | None,
    remote_name: str = "openai",
    sure_p: float = SURE_P,
) -> Verdict:
    """Decide between the embedded reading ``local`` (with its probability ``local_p``)
    and the remote reading ``remote`` (``None``: "not a driving request"); the embedded
    reading is sure from probability ``sure_p`` (``sure_p = 1``: never, even at a
    probability that rounds to 1)."""
    if local is Command.STOP:
        return Verdict(Command.STOP, "embedded", "stop-local")
    if local == remote:
        return Verdict(local, "both", "agree")
    sure = local_p >= sure_p and sure_p < 1.0
    if local is None and sure:
        return Verdict(None, "embedded", "local-sure-none")
    if local is not None and sure:
        return Verdict(local, "embedded", "local-sure")
    if remote is Command.STOP:
        return Verdict(Command.STOP, remote_name, "stop-remote")
    if remote is None:
        return Verdict(None, remote_name, "remote-none")
    return Verdict(remote, remote_name, "remote")


@dataclass(frozen=True, slots=True)
class TwoReadings:
    """One labelled line read by both readers, for :func:`trust_sweep`.

    Attributes:
        truth: the label (``fast``, ``comfort``, ``stop`` or ``none``).
        local: the embedded reading and ``local_p`` its probability.
        remote: the remote reading; ``readable`` is false when the reply could not be read
            (or the model was not asked): the embedded reading then stands at any ``sure_p``.
    """

    truth: str
    local: Command | None
    local_p: float
    remote: Command | None
    readable: bool


def trust_sweep(
    lines: list[TwoReadings], grid: tuple[float, ...] = TRUST_GRID
) -> list[dict[str, float | None]]:
    """For each ``sure_p`` of ``grid``: the accuracy over the command lines, the share of
    ``none`` lines left without a command and the STOP recall that reconciling the two
    readings with it gives (each ``None`` where the data has no such line)."""
    table = []
    for sure_p in grid:
        picked = [
            reconcile(x.local, x.local_p, x.remote, sure_p=sure_p).intent if x.readable
            else x.local
            for x in lines
        ]  # fmt: skip
        labels = [c.label if c is not None else "none" for c in picked]
        table.append(
            {
                "sure_p": sure_p,
                "accuracy": _share(lines, labels, lambda t: t != "none"),
                "none_rejection": _share(lines, labels, lambda t: t == "none"),
                "stop_recall": _share(lines, labels, lambda t: t == "stop"),
            }
        )
    return table


def _share(
    lines: list[TwoReadings], labels: list[str], keep: Callable[[str], bool]
) -> float | None:
    hits = [p == x.truth for x, p in zip(lines, labels, strict=True) if keep(x.truth)]
    return round(sum(hits) / len(hits), 4) if hits else None
