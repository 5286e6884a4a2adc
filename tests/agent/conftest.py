"""Agent tests run torch on one thread: the suite shares 2 cores with SUMO processes."""

from __future__ import annotations

import torch

torch.set_num_threads(1)
