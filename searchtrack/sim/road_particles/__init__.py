"""Paper 000's road tracking with the RBPF: the closed-loop episode and its planners
(exhaustive RHC, RL, ideal, random), the Gymnasium environment and RL training, and the offline
filter of recorded road detections."""
