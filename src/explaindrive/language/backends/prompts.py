"""What the ``openai`` backend sends: the paper's prompts (section 4; LLM-1's with one
sentence added, docs/language.md), the GBNF grammars sent with ``openai.grammar``, and the
user message of LLM-2 and LLM-3 built from a state record."""

from __future__ import annotations

from explaindrive.language.backends.replies import NOT_A_REQUEST
from explaindrive.language.explanation.decision import EXPLAIN_TAG, NO_EXPLANATION_TAG
from explaindrive.language.explanation.summary import (
    StateRecord,
    describe_action,
    environment_summary,
    history_summary,
)

# The paper's prompts, verbatim (section 4), LLM-1's with one sentence added.
PAPER_INTENT_PROMPT = (
    "You are an autonomous taxi's AI assistant. Reformulate the passenger's request into a "
    "direct instruction about how the vehicle should drive. The instruction must correspond "
    "to one of the following driving styles: drive faster, drive more carefully, or stop. At "
    'the end, confirm the reformulation using the following format: "You want me to '
    '[action], is this correct?" Do not provide multiple options or add any extra text. Only '
    "output the direct confirmation question."
)
# The deviation (docs/language.md): a way to say that the line is not a driving request.
NOT_A_REQUEST_INSTRUCTION = (
    " If the passenger's words are not a request about how the vehicle should drive, "
    f"output exactly: {NOT_A_REQUEST}"
)
INTENT_PROMPT = PAPER_INTENT_PROMPT + NOT_A_REQUEST_INSTRUCTION
DECISION_PROMPT = """You are an AI reasoning module for an autonomous taxi. Your task is to output exactly ONE of:
- [EXPLAIN]
- [NO EXPLANATION NEEDED]

Principles to decide:

1) Return [EXPLAIN] only if the vehicle’s present action clearly conflicts
or delays the user’s request for a clear safety reason (e.g., decelerating
when asked for driving faster, or harsh acceleration or deceleration when
asked for a comfortable ride).

2) Return [NO EXPLANATION NEEDED] for behavior that is ordinary, supportive,
or neutral with respect to the request (e.g., maintaining speed when user
asked for comfort, smooth acceleration/braking).

3) Multiple reasons: If several safety reasons exist, internally consider
the most safety-critical one.
Output only the tag. Do not include any justification or text besides the
tag."""  # noqa: E501
INTENT_GRAMMAR = (
    'root ::= "You want me to " ("drive faster" | "drive more carefully" | "stop") '
    f'", is this correct?" | "{NOT_A_REQUEST}"'
)
"""GBNF of LLM-1's reply (sent with ``openai.grammar``): a template question or
:data:`~explaindrive.language.backends.replies.NOT_A_REQUEST`."""
DECISION_GRAMMAR = f'root ::= "{EXPLAIN_TAG}" | "{NO_EXPLANATION_TAG}"'
"""GBNF of LLM-2's reply (sent with ``openai.grammar``): one of the two tags."""
EXPLAIN_PROMPT = """You are an AI assistant inside an autonomous taxi. Your job is to explain
to the passenger why the vehicle’s action seems to contradict their request.
When that happens, briefly explain the most safety-relevant nearby reason
for the vehicle’s behavior, using a friendly and reassuring tone. Keep
it concise."""

_REQUEST_TEXT = {"fast": "drive faster", "comfort": "drive more carefully", "stop": "stop"}


def situation_message(record: StateRecord, cutoff_m: float) -> str:
    """The user message of LLM-2/LLM-3: request, action, environment summary and, from a
    ride, what the passenger has felt so far (:func:`history_summary`)."""
    felt = history_summary(record)
    return (
        f"Passenger request: {_REQUEST_TEXT[record.request]}\n"
        f"Vehicle action: {describe_action(record.action)}\n"
        f"Environment: {environment_summary(record, cutoff_m)}"
        + (f"\nSo far: {felt}" if felt else "")
    )
