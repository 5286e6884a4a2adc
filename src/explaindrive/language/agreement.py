"""When the remote model and the embedded interpreter read a line differently.

With the ``openai`` backend every line is read twice: by the embedded interpreter
(first, offline, with class probabilities) and by the remote model. The policy, one
rule per case, in the order they are tried:

1. ``stop-local``: the embedded reading is STOP. It is answered at once; the remote
   model is not asked (the STOP lane).
2. ``agree``: both readings are the same (a command, or not a driving request).
3. ``local-sure-none``: the embedded reading is "not a request" with probability at least
   :data:`SURE_P`. A remote command, STOP included, does not turn it into a driving
   change.
4. ``local-sure``: the embedded reading is a command with probability at least
   :data:`SURE_P`; it stands against a different remote command (STOP included) or a
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

Only a well-formed remote reply takes part; a malformed one, an error or a call past its
deadline leaves the embedded reading alone (a fallback, counted as such).
"""

from __future__ import annotations

from dataclasses import dataclass

from explaindrive.commands import Command

SURE_P = 0.8  # the embedded reading's probability from which it is not overridden


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
) -> Verdict:
    """Decide between the embedded reading ``local`` (with its probability ``local_p``)
    and the remote reading ``remote`` (``None``: "not a driving request")."""
    if local is Command.STOP:
        return Verdict(Command.STOP, "embedded", "stop-local")
    if local == remote:
        return Verdict(local, "both", "agree")
    sure = local_p >= SURE_P
    if local is None and sure:
        return Verdict(None, "embedded", "local-sure-none")
    if local is not None and sure:
        return Verdict(local, "embedded", "local-sure")
    if remote is Command.STOP:
        return Verdict(Command.STOP, remote_name, "stop-remote")
    if remote is None:
        return Verdict(None, remote_name, "remote-none")
    return Verdict(remote, remote_name, "remote")
