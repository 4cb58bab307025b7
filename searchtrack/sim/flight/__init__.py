"""Flights: a trajectory controller flown closed loop with wind and noise (:mod:`.loop`), planner
routes flown by it (:mod:`.routes`) and paper 004's E7 flight (:mod:`.e7`)."""
