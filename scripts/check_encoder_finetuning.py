"""Would fine-tuning the sentence encoder help LLM-1? Frozen against fine-tuned, same split.

    python scripts/check_encoder_finetuning.py [--fit-devs 7] [--epochs 1] [--lr 1e-4]

The shipped classifier sits on a frozen all-MiniLM-L6-v2. This check fine-tunes the encoder
(all its weights, with a cosine softmax head over the four labels) on the training requests
and the development splits ``dev-1`` ... ``dev-K``, then fits the classifier of the
shipped recipe (its hyper-parameters, STOP threshold and none margin) over the fine-tuned
embeddings and over the frozen ones, and judges both on the requests neither saw: the
other development splits and ``reserve``. The blind test file is never read.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np
import torch
from numpy.typing import NDArray

from explaindrive.language.data import TRAIN_CSV, data_path
from explaindrive.language.intent.classifier import NONE, STOP, IntentClassifier, decide_rows
from explaindrive.language.intent.datasets import INTENT_LABELS, CommandExample, load_commands
from explaindrive.language.intent.encoders import minilm_model_dir
from explaindrive.language.intent.features import features_from_embeddings, normalize_text
from explaindrive.language.intent.training import Encoded, Hyper, Selection, fit_final

LOGIT_SCALE = 20.0  # cosine similarities times this are the head's logits
BATCH = 32


def dev_index(split: str) -> int | None:
    return int(split[4:]) if split.startswith("dev-") else None


def embed(model: Any, texts: list[str]) -> NDArray[np.float32]:
    model.eval()
    parts = []
    with torch.inference_mode():
        for i in range(0, len(texts), 128):
            out = model(model.preprocess(texts[i : i + 128]))["sentence_embedding"]
            parts.append(torch.nn.functional.normalize(out, dim=-1).numpy())
    return np.vstack(parts).astype(np.float32)


def fine_tune(model: Any, texts: list[str], y: NDArray[np.int64], epochs: int, lr: float) -> None:
    """Class-weighted cross-entropy through a cosine head; warm-up then linear decay."""
    head = torch.nn.Linear(model.get_embedding_dimension(), len(INTENT_LABELS))
    weight = torch.tensor(len(y) / (len(INTENT_LABELS) * np.bincount(y, minlength=4)))
    opt = torch.optim.AdamW(
        [{"params": model.parameters(), "lr": lr}, {"params": head.parameters(), "lr": 1e-3}],
        weight_decay=0.01,
    )
    steps = epochs * -(-len(texts) // BATCH)
    warm = max(1, steps // 10)
    sched = torch.optim.lr_scheduler.LambdaLR(
        opt, lambda s: s / warm if s < warm else max(0.0, (steps - s) / (steps - warm))
    )
    labels = torch.tensor(y)
    rng = np.random.default_rng(0)
    for epoch in range(epochs):
        model.train()
        t0, total = time.perf_counter(), 0.0
        for idx in np.array_split(rng.permutation(len(texts)), steps // epochs):
            emb = model(model.preprocess([texts[j] for j in idx]))["sentence_embedding"]
            logits = head(torch.nn.functional.normalize(emb, dim=-1)) * LOGIT_SCALE
            loss = torch.nn.functional.cross_entropy(logits, labels[idx], weight=weight.float())
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            total += loss.item() * len(idx)
        print(f"epoch {epoch}: loss {total / len(texts):.4f} in {time.perf_counter() - t0:.0f} s")


def judge(
    name: str,
    fit: list[CommandExample],
    held: list[CommandExample],
    emb_fit: NDArray[np.float32],
    emb_held: NDArray[np.float32],
    shipped: IntentClassifier,
) -> None:
    """Fit the shipped recipe on ``fit`` and print its figures on ``held``."""
    hyper = Hyper(100.0, shipped.spec.ngram_weight, shipped.spec.cue_weight, shipped.lr_weight)
    sel = Selection(hyper, 0.0, shipped.stop_threshold, shipped.none_margin, 0.0, 0)
    labels = lambda rows: np.array([INTENT_LABELS.index(r.label) for r in rows])  # noqa: E731
    clf = fit_final(Encoded([r.text for r in fit], labels(fit), emb_fit), [], sel)
    y = labels(held)
    p = clf.proba(features_from_embeddings(emb_held, [r.text for r in held], clf.spec))
    pred = decide_rows(p, clf.stop_threshold, clf.none_margin)
    cmd = y != NONE
    print(
        f"| {name} | {np.mean(pred == y):.3f} | {np.mean(pred[cmd] == y[cmd]):.3f} "
        f"| {np.mean(pred[~cmd] == NONE):.3f} | {np.mean(pred[y == STOP] == STOP):.3f} "
        f"| {int(np.sum((pred == STOP) & (y != STOP)))} |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fit-devs", type=int, default=7, help="fit on dev-1 ... dev-K")
    parser.add_argument("--epochs", type=int, default=1)
    parser.add_argument("--lr", type=float, default=1e-4, help="encoder learning rate")
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    torch.manual_seed(0)
    torch.set_num_threads(args.threads)
    from sentence_transformers import SentenceTransformer

    rows = load_commands(data_path(TRAIN_CSV))
    in_fit = [r.split == "train" or 0 < (dev_index(r.split) or 0) <= args.fit_devs for r in rows]
    fit = [r for r, f in zip(rows, in_fit, strict=True) if f]
    held = [r for r, f in zip(rows, in_fit, strict=True) if not f]
    print(f"fit on {len(fit)} requests, judged on {len(held)} (dev-{args.fit_devs + 1}+, reserve)")
    shipped = IntentClassifier.load()
    model = SentenceTransformer(str(minilm_model_dir()), device="cpu", local_files_only=True)
    texts_fit = [normalize_text(r.text) for r in fit]
    texts_held = [normalize_text(r.text) for r in held]
    frozen = (embed(model, texts_fit), embed(model, texts_held))
    y_fit = np.array([INTENT_LABELS.index(r.label) for r in fit])
    fine_tune(model, texts_fit, y_fit, args.epochs, args.lr)
    tuned = (embed(model, texts_fit), embed(model, texts_held))
    print("\n| encoder | accuracy (4 classes) | accuracy (3 commands) | off-topic left | "
          "STOP recall | false STOPs |\n|---|---|---|---|---|---|")  # fmt: skip
    judge("frozen (shipped)", fit, held, *frozen, shipped)
    judge(f"fine-tuned, {args.epochs} epoch(s), lr {args.lr:g}", fit, held, *tuned, shipped)


if __name__ == "__main__":
    main()
