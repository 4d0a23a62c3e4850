"""The exceptions the library raises; each message is one line that names what went wrong."""

from __future__ import annotations


class CotmError(Exception):
    """Base of every error of this package."""


class ParameterError(CotmError, ValueError):
    """A parameter, setting or option value that cannot be used; the message names the field."""


class SolverError(CotmError, RuntimeError):
    """A solver failed: non-zero exit, timeout, missing output, or paths no retry recovered."""


class EngineError(SolverError):
    """No usable solver binary or module; the message says what to install."""


class IncompleteError(CotmError, RuntimeError):
    """A completeness check failed: equilibria may be missing (the result is kept, not trusted)."""


class CertificateError(CotmError, RuntimeError):
    """The proof and the solver's table differ: an equilibrium missing, unproved, or mislabelled.

    `certificate` holds the whole certificate (what was proved, and every difference)."""

    def __init__(self, message: str, certificate=None) -> None:
        super().__init__(message)
        self.certificate = certificate
