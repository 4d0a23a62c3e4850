"""Tables 2-4 of DETC2018-85998 as printed (the data live in cotm_bertini.paper)."""

from cotm_bertini.paper.tables import K_RATIO, TABLE2, TABLE2_COMPLEX, TABLES

TABLE3 = TABLES[1].rows
TABLE4 = TABLES[2].rows

__all__ = ["K_RATIO", "TABLE2", "TABLE2_COMPLEX", "TABLE3", "TABLE4"]
