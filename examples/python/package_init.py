"""ManiSoft: soft continuum arm simulation and the ManiSoft benchmark's environments.

    import manisoft
    env = manisoft.make_env("ALN", "clean", seed=0)      # a task (or "reach"), Gymnasium's API
    vec = manisoft.make_vec_env("reach", 64)             # a batch of arms, Gymnasium's vector API

The compiled part is manisoft._manisoft; everything public in it is here. The package's scripts
run as modules: python3 -m manisoft.evaluate (the evaluation harness), manisoft.read_dataset,
manisoft.export_zarr, manisoft.dataset_stats, manisoft.bc_baseline, manisoft.reference_policy and
manisoft.sac_executor (the SAC-trained executor).
"""
from ._manisoft import *  # noqa: F401,F403
