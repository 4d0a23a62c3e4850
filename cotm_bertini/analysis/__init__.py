"""Analysis: endpoints into classified solutions (real, physical, stable), mechanics, checks."""
