"""`certify`: prove a solve's solutions and the completeness of its physical equilibria."""

from __future__ import annotations

from ..errors import CertificateError
from .solutions import Solutions, paper_only


def certify(res: Solutions, strict: bool = True):
    """Prove every reported solution (Krawczyk, ball arithmetic) and that no physical
    equilibrium is missing (the relaxed ones by branch and bound, the others along the parallel
    curve a1 x a2 = 0, enclosed in ball arithmetic); docs/certify.md says what exactly.

    Returns the Certificate and attaches it to `res` (`res.certificate`; `res.table` gains the
    columns `certified` and `certified_radius`; `res.save` writes them and a `certificate` block
    in run.json). With `strict` (default), a difference between the proof and the table raises
    CertificateError (the certificate is still attached: save the run to keep the evidence).
    """
    from ..analysis.certify import certify_table

    paper_only(res, "certify")
    cert = certify_table(res.params, res.table.reset_index(drop=True))  # rows by position
    res.attach_certificate(cert)
    if strict and cert.status == "contradiction":
        raise CertificateError("; ".join(cert.contradictions), cert)
    return cert
