"""Thesis 001's road missions: scenarios and their TOML files, the mission loop on a world built
once, guidance set-up and coverage memory, the thesis's scores, the mission record, its figures
and replay page, the RBPF belief as an alternative to the LRT + trackers, and the campaign
experiment (detect / track)."""
