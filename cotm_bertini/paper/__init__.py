"""The reference paper (DETC2018-85998): its tables as printed, and the row-by-row comparison."""
