"""Numbers more than one layer relies on."""

TINY = 1e-30
"""The smallest length, denominator or density DRT divides by: far below any physical quantity in
a float64 render (a squared 1e-15 m length is 1e-30), far above float64's underflow."""
