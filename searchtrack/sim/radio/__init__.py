"""Paper 002's radio-tagged objects: the settings, the closed loop (TBD-LMB or DTT filter with a
Rényi / Cauchy–Schwarz / straight planner), the r_min keep-out of the flown trajectory, recorded
runs and their offline filtering, figures, and the campaign experiment."""
