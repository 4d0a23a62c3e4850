"""Where equilibria fold, cusp and switch cables: fold curves of the paper's mechanism and of
frameworks, and the stable-count regions of a map and their completeness check."""
