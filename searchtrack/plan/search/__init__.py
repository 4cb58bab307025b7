"""Search planners of paper 004: receding-horizon exploration + refinement, lawnmower baselines."""
