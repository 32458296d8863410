"""The options several sub-commands share, one name per idea, and how ``--help`` shows them.

Every idea has one name in every command (docs/cli.md, "Vocabulary"): ``--network`` (one
network, single-channel or multichannel), ``--layouts``, ``--profiles``, ``--windows``,
``--recordings`` (those loaded), ``--holdout-recordings`` (those tested once),
``--train-recordings`` (those trained on, where they are not simply the rest). A name is
plural where any command takes a comma list for it; a command that takes one value refuses a
list, naming the flag (:func:`one_value`). Commands declare the new names only;
:func:`accept_old_spellings` adds each older spelling of :data:`RENAMED` as an alias that
still works and says on stderr, in one line, which name replaced it.
"""

from __future__ import annotations

import argparse
import math
import sys

from .. import backends, presets
from ..datasets.biotac import BIOTAC_ENV
from ..exporters import CHECK_DURATION_RANGE
from ..timestep import STEP_RANGE

#: The commands whose ``--network`` is one sPLL network (slide's and tune's are multichannel).
SINGLE_NETWORK_COMMANDS = ("report", "compare", "stability", "simulate", "response", "evaluate",
                           "robustness", "export", "fit", "chips")  # fmt: skip
#: Older spellings, each with the name that replaced it: still accepted, with one line on stderr
#: naming the new one (:func:`accept_old_spellings`).
#: ``old: (new, commands)``: the commands that spelled it so (``None``: every command with the
#: new name).
RENAMED = {
    "--params": ("--network", SINGLE_NETWORK_COMMANDS),
    "--multichannel": ("--network", ("chips", "export", "tune")),
    "--layout": ("--layouts", None),
    "--profile": ("--profiles", None),
    "--window": ("--windows", None),
    "--test-recordings": ("--holdout-recordings", None),
    "--encoder": ("--encoders", None),
    "--noise-sigma": ("--phase-noise", None),
    "--poisson": ("--rate", ("simulate",)),
}
#: The network of every command that simulates one, unless the command says why not.
DEFAULT_NETWORK = "vibtac-vary-offset-lif"
#: Spike-time jitter sd [s] of the thesis's experiments, and its draws per sample.
THESIS_PHASE_NOISE = 5e-4
THESIS_REPEATS = 3
#: Time steps [s] of the work-precision curves of clocked backends (compare, stability).
DEFAULT_DTS = "1e-4,1e-5,1e-6"
#: Mismatch draws of an analog chip profile: pooled per cell of ``report`` (its final measure)
#: and averaged per trial of ``tune`` (fewer: every trial pays for each draw).
REPORT_CHIP_DRAWS = 5
TUNE_CHIP_DRAWS = 3


class HelpFormatter(argparse.HelpFormatter):
    """``--help`` of every sub-command: each option with a default (anything but ``None``,
    ``False`` or empty) ends its help with ``(default: VALUE)``, an option with aliases
    shows its value once, after all its spellings: ``--network, --params FILE|PRESET``, and a
    description may be a callable that returns the text."""

    def add_text(self, text) -> None:
        # A description that needs a registry loaded (export's targets) is a callable, called
        # only when the help is shown, so that building the parsers loads no exporter.
        super().add_text(text() if callable(text) else text)

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if shows_default(action.default) and "%(default)" not in text:
            text += " (default: %(default)s)"
        return text

    def _format_action_invocation(self, action: argparse.Action) -> str:
        if not action.option_strings or action.nargs == 0:
            return super()._format_action_invocation(action)
        value = self._format_args(action, self._get_default_metavar_for_optional(action))
        return f"{', '.join(action.option_strings)} {value}"


def shows_default(value) -> bool:
    """Whether ``--help`` states ``value`` as an option's default."""
    return value is not argparse.SUPPRESS and value is not None and value is not False and (
        value != [] and value != ""
    )  # fmt: skip


def split_list(text: str | None) -> list[str]:
    """The items of a comma list (``"a, b,"`` -> ``["a", "b"]``; ``None`` -> ``[]``)."""
    return [item.strip() for item in (text or "").split(",") if item.strip()]


def one_value(flag: str):
    """An argparse ``type`` for a plural flag (:data:`RENAMED`'s names) in a command that takes
    one value: a comma list is refused, naming the flag."""

    def convert(text: str) -> str:
        items = split_list(text)
        if len(items) > 1:
            raise argparse.ArgumentTypeError(
                f"takes one value in this command, got {len(items)} ({', '.join(items)}); "
                f"run it once per value"
            )
        return text.strip()

    convert.__name__ = f"one value of {flag}"
    return convert


def add_one_value_argument(group, flag: str, help: str, default: str | None = None) -> None:
    """A plural flag (:data:`RENAMED`'s names) in a command that takes one value
    (:func:`one_value`), read into the singular and shown with it: ``--layouts LAYOUT`` into
    ``args.layout``."""
    name = flag.removeprefix("--").removesuffix("s")
    group.add_argument(
        flag, dest=name, type=one_value(flag), default=default, metavar=name.upper(), help=help
    )


def accept_old_spellings(parser: argparse.ArgumentParser) -> None:
    """Give every option of ``parser`` (``spll-hw COMMAND``) that :data:`RENAMED` names its
    older spellings in that command as aliases (listed after the name in ``--help``): each
    still works and prints one line on stderr naming the option that replaced it."""
    command = parser.prog.split()[-1]
    for action in list(parser._actions):
        old = [
            o
            for o, (new, where) in RENAMED.items()
            if new in action.option_strings
            and (where is None or command in where)
            and o not in parser._option_string_actions
        ]
        if not old:
            continue
        new = RENAMED[old[0]][0]
        action.option_strings.extend(old)
        for spelling in old:
            parser._option_string_actions[spelling] = action
        action.__class__ = _renamed(type(action), parser.prog, new, frozenset(old))


def _renamed(kind: type, prog: str, new: str, old: frozenset) -> type:
    """``kind`` (an argparse action class) that says on stderr when it was given by one of
    its ``old`` spellings, and then does what ``kind`` does. Given by two spellings in one
    command line (``--network A --multichannel B``), it is refused: the last would win
    silently."""

    def __call__(self, parser, namespace, values, option_string=None):
        # (the namespace this action last filled, the spelling that filled it)
        earlier_namespace, earlier = getattr(self, "given", (None, None))
        if earlier_namespace is namespace and earlier != option_string:
            parser.error(
                f"{earlier} and {option_string} both given: both spell {new} (older "
                f"spellings: {', '.join(sorted(old))}); give {new} once"
            )
        self.given = (namespace, option_string)
        if option_string in old:
            print(f"{prog}: {option_string} is deprecated, use {new}", file=sys.stderr)
        kind.__call__(self, parser, namespace, values, option_string)

    return type(kind.__name__, (kind,), {"__call__": __call__})


def add_network_argument(
    parser, default: str | None = DEFAULT_NETWORK, why: str = "", layout: bool = True
) -> None:
    """``--network FILE|PRESET`` and, with ``layout``, ``--layouts`` (one layout, into
    ``args.layout``). ``why`` says why a command's default is not :data:`DEFAULT_NETWORK`."""
    parser.add_argument(
        "--network",
        default=default,
        metavar="FILE|PRESET",
        help="sPLL network: a TOML file ([spll] and [network] tables, see spll_hw/config.py), "
        f"such as a tuning study's best.toml, or a preset: {presets.listing()}{why}",
    )
    if layout:
        what = "override the network's layout: vary-offset, time-scaled or grouped:G"
        add_one_value_argument(parser, "--layouts", what)


def add_backend_argument(parser, default: str = "golden") -> None:
    """``--backend SPEC``: the simulator of the sPLL network (``spll-hw backends`` lists them)."""
    parser.add_argument(
        "--backend",
        default=default,
        metavar="SPEC",
        help="simulator of the sPLL network: NAME[:key=value...], e.g. golden:profile=loihi2, "
        f"golden-fixed-point:profile=loihi2; backends: {', '.join(backends.names())} "
        "(spll-hw backends says which run here)",
    )


def add_noise_arguments(group, phase_noise: float, repeats: int, why: str = "") -> None:
    """``--phase-noise`` and ``--repeats``, its draws per sample;
    ``why`` says why a command's default draws are not the thesis's."""
    group.add_argument(
        "--phase-noise",
        type=float,
        default=phase_noise,
        metavar="SECONDS",
        help=f"spike-time jitter sd [s] before the features (thesis: {THESIS_PHASE_NOISE:g}; "
        "0: none)",
    )
    group.add_argument(
        "--repeats",
        type=int,
        default=repeats,
        help=f"phase-noise draws per sample (thesis: {THESIS_REPEATS}){why}",
    )


def add_encoder_settings_argument(group, help: str) -> None:
    """``--set ENC.PARAM=VALUE``, repeatable (into ``args.set``): the encoder parameters
    :func:`spll_hw.cli.inputs.encoder_overrides` reads."""
    group.add_argument("--set", action="append", default=[], metavar="ENC.PARAM=VALUE", help=help)


def add_dataset_arguments(parser) -> None:
    """The dataset options of ``evaluate``, ``report`` and ``tune``
    (:func:`spll_hw.cli.inputs.load_samples` reads them)."""
    d = parser.add_argument_group("dataset")
    d.add_argument(
        "--dataset",
        choices=("synthetic", "biotac", "folder"),
        default="synthetic",
        help="synthetic (embedded), biotac (BioTac_slide_20_50) or folder "
        "(one subfolder of wav/csv/npy recordings per class, VibTac-style)",
    )
    d.add_argument("--data", help=f"dataset folder (biotac: default ${BIOTAC_ENV})")
    d.add_argument(
        "--classes",
        help="biotac: thesis11 (default), all, or a comma list of "
        "materials (mat3, 3, BT, 'bath towel'); folder: comma list of class folders",
    )
    d.add_argument(
        "--recordings",
        help="recording numbers to load, e.g. 1-40 or 1,3,5-9 (default all): biotac: N of "
        "matX_N_bio.csv; folder: a file's position in its class folder, files sorted by name "
        "(3: the third file of every class)",
    )
    d.add_argument(
        "--holdout-recordings",
        metavar="A-B",
        help="biotac, folder: hold these recordings (numbered as --recordings) out, e.g. "
        "33-40: train on the others and test once on these, with 95 %% CIs by a bootstrap "
        "over them (tune: the study never sees them; its final networks are tested on them)",
    )
    d.add_argument("--fs", type=float, help="folder: sampling rate [Hz] of csv/npy recordings")
    d.add_argument("--duration", type=float, help="sample length [s] (default 2; synthetic: 1)")
    d.add_argument("--per-class", type=int, help="use at most this many samples per class")
    d.add_argument("--synthetic-classes", type=int, default=8, help="synthetic: classes")
    d.add_argument(
        "--synthetic-samples", type=int, default=350, help="synthetic: samples per class"
    )


def add_cv_argument(group) -> None:
    """``--cv samples|recordings``: folds of samples, or of whole recordings (evaluate,
    report)."""
    group.add_argument(
        "--cv",
        choices=("samples", "recordings"),
        default="samples",
        help="folds of samples (the thesis's) or of whole recordings (no recording in both "
        "the training and the test fold; every class needs a recording per fold)",
    )


def add_steps_argument(parser, default: str | None = None) -> None:
    """``--steps LADDER``: every clocked chip profile at each step of a ladder
    (:func:`spll_hw.cli.inputs.stepped_profiles`)."""
    parser.add_argument(
        "--steps", metavar="LADDER", default=default,
        help="time steps of every clocked chip profile, comma-separated with a unit (e.g. "
        "10,20,40,80,160us): each becomes NAME@STEP, the chip stepped that often; a step at "
        "which the chip cannot write the network is refused by name ('none': each profile at "
        "its own step)",
    )  # fmt: skip


def add_jobs_argument(parser, what: str = "worker processes") -> None:
    """``--jobs N``: ``None`` means every core (:func:`spll_hw.cli.inputs.jobs`)."""
    parser.add_argument("--jobs", type=int, help=f"{what} (default: all cores)")


#: Numeric flags that must be strictly positive (every other number must be finite and >= 0).
POSITIVE_FLAGS = frozenset({
    "--duration", "--dt", "--rate", "--periodic", "--free-freq", "--f-max", "--alpha", "--fs",
    "--folds", "--samples", "--points", "--workers", "--jobs", "--threads", "--n-spll",
    "--chip-draws", "--per-class", "--synthetic-classes", "--synthetic-samples", "--repeats",
    "--cv-repeats", "--check-duration",
})  # fmt: skip
#: Values above which a flag is probably given in the wrong unit: (limit, unit).
PLAUSIBLE = {"--phase-noise": (0.05, "seconds"), "--dt": (0.01, "seconds")}


def _ranges() -> dict[str, tuple[float, float, str]]:
    """Flags whose value [s] must also lie in a sane range ``[low, high]``: ``(low, high, what
    it is)``, refused in the parser naming the flag and the range (a step of 1e-300 s or a
    check of 1e308 s would otherwise overflow or run for ever)."""
    return {
        "--dt": (*STEP_RANGE, "a time step"),
        "--check-duration": (*CHECK_DURATION_RANGE, "a length of the check's inputs"),
    }


def checked_number(kind: type, flag: str, positive: bool):
    """An argparse ``type`` that reads ``kind`` (int or float) and refuses NaN, infinities and
    numbers below the flag's range (``> 0`` for :data:`POSITIVE_FLAGS`, else ``>= 0``) or
    outside its sane range (:func:`_ranges`), naming the range; a value past
    :data:`PLAUSIBLE` is accepted with a warning naming the unit."""
    bound = "> 0" if positive else ">= 0"
    what = "an integer" if kind is int else "a finite number"

    def convert(text: str):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {what} {bound}, got {text!r}") from None
        if not math.isfinite(value) or value < 0 or (positive and value == 0):
            raise argparse.ArgumentTypeError(f"must be {what} {bound}, got {text!r}")
        if flag in (ranges := _ranges()):
            low, high, meaning = ranges[flag]
            if not low <= value <= high:
                raise argparse.ArgumentTypeError(
                    f"must be {meaning} in [{low:g}, {high:g}] s, got {text!r}"
                )
        limit = PLAUSIBLE.get(flag)
        if limit is not None and value > limit[0]:
            print(f"warning: {flag} {text} is in {limit[1]}: {value:g} {limit[1]} is unusually "
                  f"large (above {limit[0]:g}); check the unit", file=sys.stderr)  # fmt: skip
        return value

    convert.__name__ = kind.__name__
    return convert


def check_numbers(parser: argparse.ArgumentParser) -> None:
    """Give every ``int`` or ``float`` option of ``parser`` a range-checked type
    (:func:`checked_number`), so a bad number fails in the parser, naming the flag."""
    for action in parser._actions:
        if action.type in (int, float) and action.option_strings:
            flag = action.option_strings[0]
            action.type = checked_number(action.type, flag, flag in POSITIVE_FLAGS)
