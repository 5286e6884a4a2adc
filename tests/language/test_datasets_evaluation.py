"""Shipped datasets, their loaders, and the metric definitions (hand-computed)."""

from __future__ import annotations

from collections import Counter
from difflib import SequenceMatcher

import pytest

from explaindrive.commands import Command
from explaindrive.language.backends.embedded import RuleDecider, TemplateExplainer
from explaindrive.language.config import LanguageConfig
from explaindrive.language.data import (
    BLIND_CSV,
    DECISIONS_JSONL,
    HELDOUT_CSV,
    LABELLED_CSVS,
    NEXT_HELDOUT_CSV,
    TEST_CSV,
    TRAIN_CSV,
    data_path,
)
from explaindrive.language.evaluation import (
    evaluate_decisions,
    evaluate_everyday,
    evaluate_intents,
    intent_metrics,
)
from explaindrive.language.explanation.datasets import load_decisions
from explaindrive.language.explanation.explainer import Factor, present_factors
from explaindrive.language.intent.corpus import near_copies, read_lines
from explaindrive.language.intent.datasets import (
    NEAR_SPLIT,
    RESERVE_SPLIT,
    UNSEEN_SPLIT,
    CommandExample,
    load_commands,
    training_splits,
)
from explaindrive.language.intent.interpreter import (
    IntentInterpreter,
    IntentResult,
    format_confirmation,
)

NEAR_COPY = 0.8  # character similarity (difflib ratio) from which a text counts as a near-copy


def _texts(rows: list[CommandExample]) -> set[str]:
    return {r.text.lower() for r in rows}


def _balanced(rows: list[CommandExample], kinds: set[str]) -> None:
    counts = Counter(r.label for r in rows)
    assert min(counts["fast"], counts["comfort"], counts["stop"]) >= 30 and counts["none"] >= 20
    assert kinds <= {r.kind for r in rows}


def test_training_file_splits() -> None:
    rows = load_commands(data_path(TRAIN_CSV))
    train, devs = training_splits(rows)
    reserve = [r for r in rows if r.split == RESERVE_SPLIT]
    assert len(train) >= 400 and len(devs) >= 2 and len(reserve) >= 150
    assert len(rows) == len(train) + sum(map(len, devs)) + len(reserve)
    for split in (*devs, reserve):
        assert len(split) >= 120
        _balanced(split, {"direct", "indirect", "negation", "noise"})
    # no request is in two splits
    splits = [_texts(train), *map(_texts, devs), _texts(reserve)]
    for i, a in enumerate(splits):
        for b in splits[i + 1 :]:
            assert a.isdisjoint(b)


def test_the_test_split_and_which_of_its_lines_have_a_near_copy_learned_from() -> None:
    heldout = load_commands(data_path(HELDOUT_CSV))
    assert Counter(r.label for r in heldout) == {
        "fast": 100,
        "comfort": 100,
        "stop": 100,
        "none": 270,
    }
    negated = [r for r in heldout if r.kind == "negated_stop"]
    assert len(negated) == 45 and {r.label for r in negated} == {"none"}
    hedges = Counter(r.label for r in heldout if r.kind == "hedge")
    assert hedges == {"fast": 8, "comfort": 8, "stop": 8}
    unseen = [r.text for r in heldout if r.split == UNSEEN_SPLIT]
    assert len(unseen) == 324 and {r.split for r in heldout} == {UNSEEN_SPLIT, NEAR_SPLIT}
    seen = [
        r["text"]
        for name in LABELLED_CSVS
        if name != HELDOUT_CSV
        for r in read_lines(data_path(name))
    ]
    # no line marked unseen is near a labelled line (the everyday pool was checked too when
    # the split was committed); the first lines marked near each are
    assert near_copies(unseen, seen) == set()
    near = [r.text for r in heldout if r.split == NEAR_SPLIT]
    assert near_copies(seen, near[:5]) == set(near[:5])


def test_the_next_test_split_is_apart_from_every_labelled_line() -> None:
    """The split the next model is scored on: the layout of the test split, and its
    ``unseen`` lines near no labelled line (the everyday pool was checked too when it was
    committed); a line that is also a labelled one ("Absolutely.") is marked ``near``."""
    nxt = load_commands(data_path(NEXT_HELDOUT_CSV))
    assert Counter(r.label for r in nxt) == {"fast": 100, "comfort": 100, "stop": 100, "none": 270}
    negated = [r for r in nxt if r.kind == "negated_stop"]
    assert len(negated) == 45 and {r.label for r in negated} == {"none"}
    assert Counter(r.kind for r in nxt if r.label == "stop")["park"] == 20
    seen = [r["text"] for name in LABELLED_CSVS for r in read_lines(data_path(name))]
    unseen = [r.text for r in nxt if r.split == UNSEEN_SPLIT]
    assert len(unseen) == 281 and {r.split for r in nxt} == {UNSEEN_SPLIT, NEAR_SPLIT}
    assert near_copies(unseen, seen) == set()


def test_near_copies_either_way_round() -> None:
    # "slow down please" in "slow down please now": ratio 2*16/(16+20) = 0.89 >= 0.8
    assert near_copies(["Slow down please"], ["slow down please now", "Pull over"]) == {
        "slow down please now"
    }
    # 2*9/(9+19) = 0.64 < 0.8
    assert near_copies(["pull over"], ["pull over right now"]) == set()


def test_blind_test_file() -> None:
    test = load_commands(data_path(TEST_CSV))
    assert len(test) >= 150 and {r.split for r in test} == {""}
    _balanced(test, {"direct", "indirect", "negation", "noise", "offtopic"})
    seen = _texts(load_commands(data_path(TRAIN_CSV)))
    near_copies = [
        (t.text, s)
        for t in test
        for s in seen
        if SequenceMatcher(None, t.text.lower(), s).quick_ratio() >= NEAR_COPY
        and SequenceMatcher(None, t.text.lower(), s).ratio() >= NEAR_COPY
    ]
    assert near_copies == []


def test_second_blind_test_file() -> None:
    blind = load_commands(data_path(BLIND_CSV))
    by_label = Counter(r.label for r in blind)
    assert len(blind) == 161 and by_label == {"fast": 43, "comfort": 45, "stop": 32, "none": 41}
    by_kind = Counter(r.kind for r in blind)
    assert by_kind["negated_stop"] == 17 and by_kind["offtopic"] == 40
    assert {r.label for r in blind if r.kind == "negated_stop"} == {"fast", "comfort"}
    seen = _texts(load_commands(data_path(TRAIN_CSV))) | _texts(load_commands(data_path(TEST_CSV)))
    near_copies = [
        (t.text, s)
        for t in blind
        for s in seen
        if SequenceMatcher(None, t.text.lower(), s).quick_ratio() >= NEAR_COPY
        and SequenceMatcher(None, t.text.lower(), s).ratio() >= NEAR_COPY
    ]
    assert near_copies == []


def test_training_splits_keep_file_order_and_number_the_dev_splits(tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = tmp_path / "c.csv"
    p.write_text(
        "text,label,kind,split\n"
        "a,fast,,dev-2\nb,stop,,train\nc,none,,dev-1\nd,comfort,,reserve\ne,fast,,dev-2\n"
    )
    train, devs = training_splits(load_commands(p))
    assert [r.text for r in train] == ["b"]
    assert [[r.text for r in d] for d in devs] == [["c"], ["a", "e"]]
    p.write_text("text,label,split\na,fast,train\nb,stop,dev-1\nc,stop,dev-3\n")
    with pytest.raises(ValueError, match="numbered 1 to N, got 1, 3"):
        training_splits(load_commands(p))
    p.write_text("text,label,split\na,fast,dev-1\n")
    with pytest.raises(ValueError, match="no requests of split 'train'"):
        training_splits(load_commands(p))
    p.write_text("text,label,split\na,fast,train\nb,stop,test\n")
    with pytest.raises(ValueError, match=r"c.csv:3: unknown split 'test'"):
        load_commands(p)


def test_decision_set() -> None:
    rows = load_decisions(data_path(DECISIONS_JSONL))
    assert len(rows) == 146
    assert sum(r.explain for r in rows) == 90
    with_history = [r for r in rows if r.history is not None]
    assert len(with_history) == 20  # what a passenger notices over several steps
    assert sum(r.explain for r in with_history) == 10
    giving_way = [r for r in rows if r.state.d_yield is not None]
    assert len(giving_way) == 11 and sum(r.factor is Factor.GIVE_WAY for r in giving_way) == 6
    several = [r for r in rows if r.explain and len(present_factors(r.record().nearby())) >= 3]
    assert len(several) >= 30  # the speed limit and at least two objects


def test_bad_files(tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = tmp_path / "c.csv"
    p.write_text("text,label\nhello,faster\n")
    with pytest.raises(ValueError, match=r"c.csv:2: unknown label 'faster'"):
        load_commands(p)
    p.write_text("words\nhello\n")
    with pytest.raises(ValueError, match="expected a CSV header with a text column"):
        load_commands(p)
    p.write_text("text,label\n")
    with pytest.raises(ValueError, match=r"c.csv: no rows"):
        load_commands(p)
    j = tmp_path / "d.jsonl"
    j.write_text('{"request": "fast"\n')
    with pytest.raises(ValueError, match=r"d.jsonl:1: not valid JSON"):
        load_decisions(j)
    with pytest.raises(FileNotFoundError):
        load_commands(tmp_path / "none.csv")


def test_intent_metrics_by_hand() -> None:
    truth = ["fast", "fast", "comfort", "comfort", "stop", "stop", "none", "none"]
    pred = ["fast", "comfort", "comfort", "comfort", "stop", "none", "none", "fast"]
    conf = ["You want me to drive faster, is this correct?"] * 5 + ["x", None, None]
    m = intent_metrics(truth, pred, conf)
    assert m["accuracy"] == pytest.approx(4 / 6, abs=1e-4)
    # fast P=1 R=.5 F=2/3; comfort P=2/3 R=1 F=.8; stop P=1 R=.5 F=2/3
    assert m["macro_f1"] == pytest.approx((2 / 3 + 0.8 + 2 / 3) / 3, abs=1e-4)
    assert m["per_class"]["stop"] == {"precision": 1.0, "recall": 0.5, "f1": 0.6667, "support": 2}
    # po = 4/6; pe = (2*1 + 2*3 + 2*1)/36 (the "none" prediction is its own column)
    po, pe = 4 / 6, (2 * 1 + 2 * 3 + 2 * 1) / 36
    assert m["cohen_kappa"] == pytest.approx((po - pe) / (1 - pe), abs=1e-4)
    assert m["template_compliance"] == pytest.approx(5 / 6, abs=1e-4)
    assert m["none_rejection"] == 0.5
    assert m["confusion"]["matrix"][2] == [0, 0, 1, 1]


class _Scripted(IntentInterpreter):
    """Reads a line as the command it names, ``ask`` as a STOP asked about."""

    def interpret(self, text: str) -> IntentResult:
        if text.startswith("ask"):
            q = format_confirmation(Command.STOP)
            return IntentResult(None, q, "x", False, 0.0, {}, reading="none", ask=Command.STOP)
        cmd = Command.parse(text.split()[0]) if text.split()[0] != "none" else None
        q = format_confirmation(cmd) if cmd is not None else "rephrase"
        return IntentResult(cmd, q, "x", False, 0.0, {}, reading=cmd.label if cmd else "none")


def test_lines_asked_about_are_counted_apart_from_the_commands() -> None:
    rows = [
        CommandExample("stop now", "stop"),
        CommandExample("ask 1", "stop"),
        CommandExample("none 1", "stop"),
        CommandExample("stop 2", "stop"),
        CommandExample("ask 2", "none"),
        CommandExample("none 2", "none"),
        CommandExample("fast", "fast"),
    ]
    report = evaluate_intents(_Scripted(), rows)
    # STOP read for 2 of 4 STOP requests; read or asked about for 3 of 4
    assert report["per_class"]["stop"]["recall"] == 0.5
    assert report["stop_heard"] == 0.75
    assert report["asked_stop"] == {"stop": 1, "none": 1}
    assert report["none_rejection"] == 1.0  # an ask gives no command
    everyday = evaluate_everyday(_Scripted(), ["none a", "ask b", "fast c", "none d"])
    assert (everyday["left_without_command"], everyday["left_alone"]) == (0.75, 0.5)
    assert everyday["asked_stop"] == 1 and everyday["asked"] == [
        {"text": "ask b", "command": "stop"}
    ]


def test_decisions_on_shipped_set_meet_targets() -> None:
    cfg = LanguageConfig().embedded
    report = evaluate_decisions(
        RuleDecider(cfg), TemplateExplainer(cfg), load_decisions(data_path(DECISIONS_JSONL))
    )
    assert report["accuracy"] >= 0.95 and report["factor_accuracy"] >= 0.95
    assert report["factor_accuracy_multi"] >= 0.95 and report["n_multi"] >= 30
    assert report["grounded_share"] == 1.0 and report["truthful_share"] == 1.0
    assert all(t["absent_factors"] == [] for t in report["explanations"])


def test_config_rejects_unknown_keys(tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = tmp_path / "lang.yaml"
    p.write_text("backend: embedded\nopenai:\n  timeout_s: 0.5\n  modle: x\n")
    with pytest.raises(ValueError, match="modle"):
        LanguageConfig.from_yaml(p)
    p.write_text("openai:\n  timeout_s: 0.5\n")
    assert LanguageConfig.from_yaml(p).openai.timeout_s == 0.5
    p.write_text("embedded:\n  encoder: minilm\n")  # one encoder: nothing to choose
    with pytest.raises(ValueError, match="encoder"):
        LanguageConfig.from_yaml(p)
    p.write_text("embedded:\n  encoder_threads: 1\n")
    config = LanguageConfig.from_yaml(p)
    assert config.embedded.encoder_runtime == "onnx"
    swapped = config.with_runtime("torch")
    assert swapped.embedded.encoder_runtime == "torch" and swapped.embedded.encoder_threads == 1
    with pytest.raises(ValueError, match="unknown encoder runtime 'tf'"):
        config.with_runtime("tf")
