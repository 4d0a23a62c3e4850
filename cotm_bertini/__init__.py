"""cotm-bertini: every equilibrium of a compliant tensegrity mechanism, with Bertini."""

__version__ = "0.1.0"
