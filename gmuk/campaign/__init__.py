"""Campaigns: Monte Carlo dispersions and parameter sweeps, on one process, local processes
or Dask, stored incrementally and resumable.

::

    from gmuk.campaign import AttitudeCone, Campaign, UniformBall
    c = Campaign("fcei", runs=200, seed=1,
                 dispersions={"attitude_error": AttitudeCone(math.radians(10)),
                              "position_error_m": UniformBall(100.0)},
                 fixed={"orbits": 0.01})
    report = c.run("out/fcei-mc", workers=2)            # or scheduler="tcp://…" / "local"
    table = gmuk.campaign.read_table("out/fcei-mc")     # pyarrow.Table, one row per run
    gmuk.campaign.summarize("out/fcei-mc")              # statistics table and figures

The same from the command line: ``gmuk campaign fcei --runs 200 --seed 1 --workers 2 --out
out/fcei-mc``, ``gmuk campaign --resume out/fcei-mc``, ``gmuk campaign --summary out/fcei-mc``.

dask.distributed and pyarrow are imported only when a campaign runs or its results are read
(``pip install 'gmuk[campaign]'``).
"""

from gmuk.campaign.core import Campaign, CampaignReport, execute, load_campaign, resume
from gmuk.campaign.dispersions import (
    AttitudeCone,
    Choice,
    Dispersion,
    GaussianVector,
    IntegerRange,
    Normal,
    SecondMomentScale,
    Uniform,
    UniformBall,
)
from gmuk.campaign.models import (
    MODELS,
    CampaignModel,
    FunctionModel,
    Parameter,
    RunSetup,
    get_model,
    scaled_inertia,
    supported,
)
from gmuk.campaign.store import read_table
from gmuk.campaign.summary import CampaignSummary, summarize

__all__ = [
    "MODELS",
    "AttitudeCone",
    "Campaign",
    "CampaignModel",
    "CampaignReport",
    "CampaignSummary",
    "Choice",
    "Dispersion",
    "FunctionModel",
    "GaussianVector",
    "IntegerRange",
    "Normal",
    "Parameter",
    "RunSetup",
    "SecondMomentScale",
    "Uniform",
    "UniformBall",
    "execute",
    "get_model",
    "load_campaign",
    "read_table",
    "resume",
    "scaled_inertia",
    "summarize",
    "supported",
]
