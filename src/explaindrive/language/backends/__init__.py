"""Language backends behind one registry (:mod:`~explaindrive.language.backends.registry`).

``embedded`` (offline, default) and ``openai`` (any compatible endpoint) ship with the
package (:mod:`~explaindrive.language.backends.builtin`); another backend joins with
:func:`register_backend`.
"""

from __future__ import annotations

from explaindrive.language.backends import builtin as _builtin  # registers the shipped ones
from explaindrive.language.backends.registry import (
    Backend,
    LanguageModules,
    UnknownBackendError,
    backend_names,
    check_backend,
    get_backend,
    register_backend,
    unregister_backend,
)

del _builtin

__all__ = [
    "Backend",
    "LanguageModules",
    "UnknownBackendError",
    "backend_names",
    "check_backend",
    "get_backend",
    "register_backend",
    "unregister_backend",
]
