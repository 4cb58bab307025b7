"""Toy campaign files and specs shared by the campaign tests."""

from __future__ import annotations

from pathlib import Path

from searchtrack.sim.campaigns.spec import CampaignSpec


def toy_spec(values: tuple[float, ...] = (1.0, 2.0), seeds: int = 3, *,
             fail: tuple[bool, ...] = (False,), sleep_s: float = 0.0,
             name: str = "toy-test") -> CampaignSpec:
    """A toy campaign: ``values`` × ``fail`` × ``seeds`` runs sleeping ``sleep_s`` each."""
    return CampaignSpec(name, "toy", {"sleep_s": sleep_s}, {"value": values, "fail": fail},
                        tuple(range(seeds)))


def write_toy_file(folder: Path, body: str = "[grid]\nvalue = [1.0, 2.0]\n",
                   head: str = 'name = "toy-file"\nexperiment = "toy"\nseeds = {count = 2}\n'
                   ) -> Path:
    """A campaign file in ``folder`` (``head`` then ``body``)."""
    path = folder / "campaign.toml"
    path.write_text(head + body, encoding="utf-8")
    return path
