"""Fine-tune LLM-1 on the CPU: low-rank adapters in every layer of the encoder and a
reading head, trained end to end with cross-entropy.

Run ``python -m explaindrive.language.intent.finetune`` to rebuild the shipped model
(``--out`` to write elsewhere, ``--resume`` to carry on a run that was stopped). Each epoch
sees every labelled line of the training pool (:mod:`~explaindrive.language.intent.corpus`)
and a fresh draw of everyday lines; a checkpoint is written after each epoch. The
thresholds are then chosen on the calibration pool
(:mod:`~explaindrive.language.intent.calibration`), which training never sees.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import math
import os
import random
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch

from explaindrive.language.data import INTENT_MODEL, data_path
from explaindrive.language.intent.adapter import TARGETS, AdapterSpec
from explaindrive.language.intent.calibration import choose_thresholds
from explaindrive.language.intent.corpus import Example, calibration_pool, training_pool
from explaindrive.language.intent.encoders import minilm_model_dir
from explaindrive.language.intent.model import READINGS, IntentModel, Thresholds
from explaindrive.language.intent.noise import addressed, slipped
from explaindrive.language.packaged import MINILM

log = logging.getLogger(__name__)

CHECKPOINT = "checkpoint.pt"
HEAD_SCALE = 10.0
"""The unit-norm embedding is scaled by this before the head (folded into the shipped
head's weights), so that confident logits do not need large weights."""


@dataclass(frozen=True)
class FinetuneConfig:
    """How LLM-1 is fine-tuned.

    Attributes:
        epochs: epochs of training.
        labelled_repeats: times each labelled line is seen in an epoch.
        everyday_per_epoch: everyday lines drawn afresh for each epoch.
        batch_size: lines per step.
        lr_adapter: learning rate of the adapters.
        lr_head: learning rate of the head.
        label_smoothing: cross-entropy label smoothing.
        slip_share: share of the labelled lines seen with a typing or hearing slip
            (:mod:`~explaindrive.language.intent.noise`).
        address_share: share of the labelled lines seen addressed to someone
            (:func:`~explaindrive.language.intent.noise.addressed`).
        max_tokens: lines are cut at this many tokens while training.
        spec: the adapters' rank and scale.
        seed: seed of the draws, the order and the initial adapters.
        threads: PyTorch threads.
    """

    epochs: int = 5
    labelled_repeats: int = 2
    everyday_per_epoch: int = 10000
    batch_size: int = 32
    lr_adapter: float = 5e-4
    lr_head: float = 3e-3
    label_smoothing: float = 0.0
    slip_share: float = 0.25
    address_share: float = 0.15
    max_tokens: int = 48
    spec: AdapterSpec = field(default_factory=AdapterSpec)
    seed: int = 0
    threads: int = 2


class LoRALinear(torch.nn.Module):
    """A frozen linear layer plus a trainable low-rank change (``B`` starts at zero)."""

    def __init__(self, base: torch.nn.Linear, spec: AdapterSpec, gen: torch.Generator) -> None:
        super().__init__()
        self.base = base
        self.scale = spec.scale
        fan_in = base.in_features
        self.A = torch.nn.Parameter(torch.randn(spec.rank, fan_in, generator=gen) / fan_in**0.5)
        self.B = torch.nn.Parameter(torch.zeros(base.out_features, spec.rank))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.base(x) + self.scale * ((x @ self.A.T) @ self.B.T)


class Reader(torch.nn.Module):
    """The encoder with adapters, mean pooling, normalisation and the reading head."""

    def __init__(self, model_dir: Path, spec: AdapterSpec, seed: int) -> None:
        super().__init__()
        from sentence_transformers import SentenceTransformer

        st = SentenceTransformer(str(model_dir), device="cpu", local_files_only=True)
        self.tokenizer = st.tokenizer
        bert: Any = st[0].auto_model
        for p in bert.parameters():
            p.requires_grad_(False)
        gen = torch.Generator().manual_seed(seed)
        self.adapters: dict[str, LoRALinear] = {}
        for name, module in list(bert.named_modules()):
            if TARGETS.search(name) and isinstance(module, torch.nn.Linear):
                wrapped = LoRALinear(module, spec, gen)
                parent, _, child = name.rpartition(".")
                setattr(bert.get_submodule(parent), child, wrapped)
                self.adapters[name] = wrapped
        self.bert = bert
        self.head = torch.nn.Linear(bert.config.hidden_size, len(READINGS))

    def embed(self, texts: list[str], max_tokens: int) -> torch.Tensor:
        enc = self.tokenizer(
            texts, padding=True, truncation=True, max_length=max_tokens, return_tensors="pt"
        )
        out = self.bert(input_ids=enc["input_ids"], attention_mask=enc["attention_mask"])
        mask = enc["attention_mask"].unsqueeze(-1).float()
        pooled = (out.last_hidden_state * mask).sum(1) / mask.sum(1).clamp(min=1e-9)
        return torch.nn.functional.normalize(pooled, dim=-1)

    def forward(self, texts: list[str], max_tokens: int) -> torch.Tensor:
        return self.head(HEAD_SCALE * self.embed(texts, max_tokens))

    def to_model(self, base_sha256: str, spec: AdapterSpec) -> IntentModel:
        adapters = {
            name: (
                m.A.detach().numpy().astype(np.float32),
                m.B.detach().numpy().astype(np.float32),
            )
            for name, m in self.adapters.items()
        }
        return IntentModel(
            adapters,
            spec,
            (HEAD_SCALE * self.head.weight.detach().numpy()).astype(np.float32),
            self.head.bias.detach().numpy().astype(np.float32),
            Thresholds(0.5, 0.5),
            base_sha256,
        )


def _epoch_lines(
    labelled: list[Example], everyday: list[Example], cfg: FinetuneConfig, epoch: int
) -> list[Example]:
    rng = random.Random(cfg.seed * 1000 + epoch)
    drawn = rng.sample(everyday, min(cfg.everyday_per_epoch, len(everyday)))
    seen = []
    for e in labelled * cfg.labelled_repeats:
        text = addressed(e.text, rng) if rng.random() < cfg.address_share else e.text
        text = slipped(text, rng) if rng.random() < cfg.slip_share else text
        seen.append(e if text == e.text else dataclasses.replace(e, text=text))
    lines = seen + drawn
    rng.shuffle(lines)
    return lines


def train(out_dir: Path, cfg: FinetuneConfig, resume: bool = False) -> tuple[Reader, float]:
    """Fine-tune a reader; checkpoints go to ``out_dir``.

    Returns:
        the trained reader and the CPU time of the training [s].
    """
    torch.manual_seed(cfg.seed)
    torch.set_num_threads(cfg.threads)
    labelled, everyday = training_pool()
    reader = Reader(minilm_model_dir(), cfg.spec, cfg.seed)
    trainable = [p for m in reader.adapters.values() for p in (m.A, m.B)]
    opt = torch.optim.AdamW(
        [
            {"params": trainable, "lr": cfg.lr_adapter},
            {"params": list(reader.head.parameters()), "lr": cfg.lr_head},
        ],
        weight_decay=0.01,
    )
    per_epoch = len(labelled) * cfg.labelled_repeats + min(cfg.everyday_per_epoch, len(everyday))
    steps_per_epoch = math.ceil(per_epoch / cfg.batch_size)
    total = cfg.epochs * steps_per_epoch
    sched = torch.optim.lr_scheduler.LambdaLR(opt, lambda s: _lr_factor(s, total))
    loss_fn = torch.nn.CrossEntropyLoss(label_smoothing=cfg.label_smoothing)
    out_dir.mkdir(parents=True, exist_ok=True)
    start, cpu = _restore(out_dir, reader, opt, sched) if resume else (0, 0.0)
    for epoch in range(start, cfg.epochs):
        t0 = time.process_time()
        lines = _epoch_lines(labelled, everyday, cfg, epoch)
        reader.train()
        losses: list[float] = []
        for i in range(0, len(lines), cfg.batch_size):
            batch = lines[i : i + cfg.batch_size]
            logits = reader([e.text for e in batch], cfg.max_tokens)
            target = torch.tensor([READINGS.index(e.label) for e in batch])
            loss = loss_fn(logits, target)
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            losses.append(loss.item())
            if len(losses) % 100 == 0:
                log.info("epoch %d step %d loss %.4f", epoch, len(losses), np.mean(losses[-100:]))
        cpu += time.process_time() - t0
        log.info("epoch %d done: loss %.4f, CPU %.0f s", epoch, np.mean(losses), cpu)
        state = {"epoch": epoch + 1, "cpu_s": cpu, "state": reader.state_dict()}
        state.update(opt=opt.state_dict(), sched=sched.state_dict())
        _save_checkpoint(out_dir / CHECKPOINT, state)
    return reader, cpu


def _save_checkpoint(path: Path, state: dict[str, Any]) -> None:
    """Write ``state`` next to ``path`` and rename it into place: a run killed while
    writing keeps its previous checkpoint."""
    staged = path.with_name(path.name + ".tmp")
    torch.save(state, staged)
    os.replace(staged, path)


def _lr_factor(step: int, total: int) -> float:
    warm = max(1, total // 20)
    if step < warm:
        return (step + 1) / warm
    return max(0.0, (total - step) / max(1, total - warm))


def _restore(out_dir: Path, reader: Reader, opt: Any, sched: Any) -> tuple[int, float]:
    ckpt = out_dir / CHECKPOINT
    if not ckpt.is_file():
        raise FileNotFoundError(f"--resume: no checkpoint in {out_dir}")
    state = torch.load(ckpt, map_location="cpu", weights_only=True)
    reader.load_state_dict(state["state"])
    opt.load_state_dict(state["opt"])
    sched.load_state_dict(state["sched"])
    return int(state["epoch"]), float(state["cpu_s"])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description="Fine-tune LLM-1 (see the module docstring).")
    ap.add_argument("--out", type=Path, default=None, help="model file (default: shipped)")
    ap.add_argument("--work", type=Path, default=Path("runs/intent"), help="checkpoints")
    ap.add_argument("--epochs", type=int, default=FinetuneConfig.epochs)
    ap.add_argument("--resume", action="store_true")
    ap.add_argument(
        "--calibrate", type=Path, default=None, help="only choose the thresholds of this model file"
    )
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s")
    cfg = FinetuneConfig(epochs=args.epochs)
    try:
        if args.calibrate is not None:
            print(calibrate(args.calibrate))
            return 0
        reader, cpu = train(args.work, cfg, args.resume)
        out = args.out or data_path(INTENT_MODEL)
        reader.to_model(MINILM.sha256, cfg.spec).save(out)
        print(calibrate(out))
    except (FileNotFoundError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {out}; fine-tuning CPU time {cpu:.0f} s")
    return 0


def calibrate(path: Path) -> str:
    """Choose the thresholds of the model in ``path`` on the calibration pool, as it runs
    (the merged encoder on ONNX Runtime), and store them there.

    Returns:
        the report with the risk-coverage curve.
    """
    from explaindrive.language.intent.reader import LineReader

    reader = LineReader(path)
    pool = calibration_pool()
    p = reader.model.proba(reader.embed([e.text for e in pool]))
    thresholds, report = choose_thresholds(reader.model, p, [e.label for e in pool])
    dataclasses.replace(reader.model, thresholds=thresholds).save(path)
    return report


if __name__ == "__main__":
    raise SystemExit(main())
