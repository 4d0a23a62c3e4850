"""Tables 2-4 of DETC2018-85998 as printed (the data live in cotm_bertini.paper), and how a
solutions table is matched against them (tests/test_cases.py, tests/test_paper_real.py)."""

import numpy as np
from physics import angle_distance

from cotm_bertini.paper.tables import K_RATIO, TABLE2, TABLE2_COMPLEX, TABLES

TABLE3 = TABLES[1].rows
TABLE4 = TABLES[2].rows

__all__ = ["K_RATIO", "TABLE2", "TABLE2_COMPLEX", "TABLE3", "TABLE4", "match_rows", "unit"]


def unit(text: str) -> float:
    """One unit of the last printed decimal."""
    decimals = len(text.split(".")[1]) if "." in text else 0
    return 10.0**-decimals


def match_rows(table_rows, solutions):
    """For each printed row, the nearest real solution and its distance in degrees."""
    real = solutions[solutions["is_real"]]
    out = []
    for row in table_rows:
        d = [
            max(angle_distance(row[0], a), angle_distance(row[1], b))
            for a, b in zip(real["gamma1_deg"], real["gamma2_deg"], strict=True)
        ]
        k = int(np.argmin(d))
        out.append((d[k], real.iloc[k]))
    return out
