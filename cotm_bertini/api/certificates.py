"""`certify`: prove a solve's solutions and the completeness of its physical equilibria."""

from __future__ import annotations

from ..errors import CertificateError, ParameterError
from ..params import Params
from .solutions import Solutions


def certify(res: Solutions, strict: bool = True):
    """Prove every reported solution (Krawczyk, ball arithmetic) and that no physical
    equilibrium is missing (the relaxed ones by branch and bound, the others along the parallel
    curve a1 x a2 = 0, enclosed in ball arithmetic); docs/certify.md says what exactly.

    A framework (cb.Framework): every real row proved on its taut set's system, with its
    consistency and kind; completeness by branch and bound where its poses form a circle or a
    torus (cables included); elsewhere the status is 'rows proved' and the
    statement says completeness is not proved (docs/certify.md, "Frameworks").

    Returns the Certificate and attaches it to `res` (`res.certificate`; `res.table` gains the
    columns `certified` and `certified_radius`; `res.save` writes them and a `certificate` block
    in run.json). With `strict` (default), a difference between the proof and the table raises
    CertificateError (the certificate is still attached: save the run to keep the evidence).
    """
    if res.settings.only != "all":
        raise ParameterError(
            f"only = {res.settings.only!r}: the certificate proves that no equilibrium of any "
            "kind is missing; certify a solve with only='all'"
        )
    table = res.table.reset_index(drop=True)  # rows by position
    if isinstance(res.params, Params):
        from ..analysis.certify.mechanism import certify_table

        cert = certify_table(res.params, table)
    else:
        from ..analysis.certify.framework import certify_framework_table

        cert = certify_framework_table(res.params, table)
    res.attach_certificate(cert)
    if strict and cert.status == "contradiction":
        raise CertificateError("; ".join(cert.contradictions), cert)
    return cert
