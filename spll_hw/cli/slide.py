"""``spll-hw slide``: accuracy against time into the slide of a multichannel network on BioTac,
beside the single-channel pipeline and the published spiking baselines.

Examples::

    spll-hw slide --data ../shared/datasets/biotac_slide_20_50 --out reports/slide
    spll-hw slide --network my-multichannel.toml --windows 0.5,1,2 --train-recordings 1-32
"""

from __future__ import annotations

import argparse
import os

from ..datasets.biotac import BIOTAC_ENV
from ..multichannel import presets
from .arguments import add_backend_argument, add_jobs_argument

#: The command's line in ``spll-hw --help``.
HELP = "BioTac accuracy against time into the slide: every channel through its own sPLL network"
#: What ``spll-hw slide --help`` says first.
DESCRIPTION = (
    "Decide the material from the first T seconds of each BioTac recording, for several T, with "
    "a multichannel network (every channel through its own encoder and sPLL network, TDE rates "
    "concatenated, ridge classifier) and the single-channel pipeline (pac only); trained on "
    "--train-recordings, scored once on --holdout-recordings, on the thesis's 11 materials and all "
    "20, with 95 % CIs by a bootstrap over test recordings. Writes summary.md, results.json and "
    "accuracy_over_time.png (the published SNN/LSTM/SVM curves of Taunyazov et al. beside)."
)
#: Default multichannel network (:mod:`spll_hw.multichannel.presets`).
DEFAULT_NETWORK = "biotac-multichannel-lif"
#: Default single-channel network (pac; its [encoder] table is its encoder).
DEFAULT_SINGLE = "biotac-tuned-time-scaled-lif"


def add_arguments(p: argparse.ArgumentParser) -> None:
    d = p.add_argument_group("data")
    d.add_argument("--data", help=f"BioTac_slide_20_50 folder (default ${BIOTAC_ENV})")
    d.add_argument(
        "--train-recordings",
        default="1-32",
        metavar="A-B",
        help="recording numbers the classifier trains on",
    )
    d.add_argument(
        "--holdout-recordings",
        dest="test_recordings",
        default="33-40",
        metavar="A-B",
        help="recording numbers it is scored on, once (never tune on them)",
    )
    d.add_argument(
        "--windows",
        default="0.25,0.5,1,2,4",
        metavar="SECONDS",
        help="comma list of decision times into the slide [s] (multiples of 10 ms)",
    )
    n = p.add_argument_group("networks")
    n.add_argument(
        "--network",
        default=DEFAULT_NETWORK,
        metavar="FILE|PRESET",
        help="multichannel network: a TOML file of [[channel]] tables "
        f"(spll_hw/multichannel/config.py) or a preset: {', '.join(presets.names())}",
    )
    n.add_argument(
        "--channels",
        metavar="LIST",
        help="keep only these channels of --network (an ablation): comma list of its channels, "
        "'electrodes' for ele1-ele19 (default: all of them)",
    )
    n.add_argument(
        "--single",
        default=DEFAULT_SINGLE,
        metavar="FILE|PRESET",
        help="the single-channel pipeline's network (pac; its [encoder], else LIF "
        "defaults); 'none' to leave it out",
    )
    add_backend_argument(n)
    n.add_argument(
        "--group-steps",
        metavar="CHANNEL=STEP,...",
        help="separate clocks: run the [[channel]] table holding CHANNEL on --backend's chip "
        "profile stepped every STEP (its own chip), e.g. pac=80us,ele1=640us with --backend "
        "golden-fixed-point:profile=loihi2; a step the chip cannot write the table's network at "
        "is refused, naming the steps that can (default: every table at the profile's own step)",
    )
    c = p.add_argument_group("classifier and run")
    c.add_argument("--alpha", type=float, default=1.0, help="ridge L2 penalty")
    c.add_argument(
        "--alpha-cv",
        action="store_true",
        help="choose the fixed windows' ridge penalty per window and class set among 0.1-1000 "
        "by 5-fold CV by recording on the training recordings (issue 60: +17 points at 0.5 "
        "and 1 s on recordings 25-32; --alpha stays the readout's)",
    )
    c.add_argument(
        "--window-parts",
        type=int,
        default=1,
        metavar="N",
        help="split every fixed window into N equal parts and give the ridge every TDE's rate "
        "in each part (N times the sPLLs as features; 1: the rates over the whole window); "
        "issue 60 chose 4 with --alpha-cv by 4-fold CV on recordings 1-32 (+7 points at "
        "0.5 and 1 s, +4 at 2 s)",
    )
    c.add_argument(
        "--readout",
        action="store_true",
        help="also decide while sliding: the multichannel network's ridge as integrate-and-fire "
        "readout neurons with winner-take-all, on causally encoded spikes of the longest window "
        "(accuracy against time to decision, float and --readout-bits integer weights; "
        "readout.png); the trained readouts go to OUT/readouts/SET-WIDTH.npz, which "
        "spll-hw export --network FILE --readout exports with the network",
    )
    c.add_argument(
        "--readout-train",
        choices=("prefixes", "end", "staged"),
        default="prefixes",
        help="what the readout's ridge trains on: the training recordings' rates over prefixes "
        "of several lengths (0.25, 0.5, 1, 2 s and the longest window; every score plus 1, so "
        "a membrane rises from the start: it decides early) or over the longest window only "
        "(best at the end, poor early); staged: five readouts that take turns (switched at "
        "0.5, 1, 2 and 3 s), each trained on its own stretch's prefixes, ridge alpha 100, integer "
        "weights scaled per channel and class (issue 60: early as prefixes and as good as the "
        "end training at the end; exports with --to nir-standard)",
    )
    c.add_argument(
        "--readout-bits",
        default="8,4",
        metavar="LIST",
        help="comma list of integer widths of the readout's weights and bias",
    )
    c.add_argument("--seed", type=int, default=0, help="seed of the bootstrap")
    add_jobs_argument(c, "encoder processes and engine threads")
    c.add_argument("--out", default=os.path.join("reports", "slide"), help="report folder")
    c.add_argument("--quiet", action="store_true", help="no progress bars")
