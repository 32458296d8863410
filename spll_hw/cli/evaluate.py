"""``spll-hw evaluate``: run the texture pipeline on a dataset and write a report folder.

Examples::

    spll-hw evaluate                                   # embedded synthetic textures
    spll-hw evaluate --dataset biotac --data ../shared/datasets/biotac_slide_20_50 \\
        --encoders lif,pacinian,peak --features spectrum,sfft,isi --out reports/biotac
    spll-hw evaluate --dataset folder --data vibtac/ --fs 8000 --set lif.gain=3000
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys

from .common import add_backend_argument, checked_backend

DATASETS = ("synthetic", "biotac", "folder")
#: Environment variable naming a BioTac_slide_20_50 copy (default of ``--data`` for biotac).
BIOTAC_ENV = "SPLL_HW_BIOTAC_DIR"


def add_dataset_arguments(p: argparse.ArgumentParser) -> None:
    """The dataset options shared by ``evaluate`` and ``report`` (read by :func:`load_samples`)."""
    d = p.add_argument_group("dataset")
    d.add_argument(
        "--dataset",
        choices=DATASETS,
        default="synthetic",
        help="synthetic (embedded, default), biotac (BioTac_slide_20_50) or folder "
        "(one subfolder of wav/csv/npy recordings per class, VibTac-style)",
    )
    d.add_argument("--data", help=f"dataset folder (biotac: default ${BIOTAC_ENV})")
    d.add_argument(
        "--classes",
        help="biotac: thesis11 (default), all, or a comma list of "
        "materials (mat3, 3, BT, 'bath towel'); folder: comma list of class folders",
    )
    d.add_argument(
        "--recordings", help="biotac: recording numbers, e.g. 1-40 or 1,3,5-9 (default all)"
    )
    d.add_argument(
        "--test-recordings",
        metavar="A-B",
        help="biotac: hold these recordings out (e.g. 33-40): train on the others, test once "
        "on these, with 95 %% CIs by a bootstrap over the test recordings",
    )
    d.add_argument("--fs", type=float, help="folder: sampling rate [Hz] of csv/npy recordings")
    d.add_argument("--duration", type=float, help="sample length [s] (default 2; synthetic: 1)")
    d.add_argument("--per-class", type=int, help="use at most this many samples per class")
    d.add_argument("--synthetic-classes", type=int, default=8, help="synthetic: classes (8)")
    d.add_argument(
        "--synthetic-samples", type=int, default=350, help="synthetic: samples per class (350)"
    )


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "evaluate",
        help="texture pipeline: encoders, features, ridge classifier, report folder",
        description="Encode a tactile dataset into spikes, extract features (pressure spectrum, "
        "sFFT, ISI histogram, sPLL network), cross-validate a ridge classifier and write a report "
        "folder (summary.md, results.json, PNG plots).",
    )
    add_dataset_arguments(p)
    e = p.add_argument_group("encoders and features")
    e.add_argument(
        "--encoders", default="lif,pacinian,peak", help="comma list of lif, pacinian, peak"
    )
    e.add_argument(
        "--features",
        default="spectrum,sfft,isi",
        help="comma list of spectrum, sfft, isi, spll (default spectrum,sfft,isi)",
    )
    e.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="ENC.PARAM=VALUE",
        help="encoder parameter, e.g. lif.gain=3000, pacinian.model=2, "
        "pacinian.rms_um=none, peak.cutoff=none, peak.spectrum=pressure (repeatable)",
    )
    e.add_argument(
        "--isi-spacing",
        choices=("linear", "geometric"),
        default="linear",
        help="ISI histogram bins over 1-100 ms (default linear)",
    )
    e.add_argument(
        "--network",
        default="biotac-vary-offset-lif",
        help="sPLL network: a preset from the thesis's Tables 6-7, "
        "<biotac|vibtac>-<vary-offset|time-scaled>-<lif|pacinian|peak>, or a network TOML file "
        "such as a tuning study's best.toml ({encoder} is replaced by each encoder's name); "
        "a file's [encoder] table sets the encoder it was tuned on (--set overrides it)",
    )
    add_backend_argument(e)
    e.add_argument(
        "--phase-noise",
        type=float,
        default=0.0,
        help="spike-time jitter sd [s] before feature extraction (thesis: 5e-4)",
    )
    e.add_argument(
        "--repeats", type=int, default=1, help="noise draws with --phase-noise (thesis: 3)"
    )
    c = p.add_argument_group("classifier and run")
    c.add_argument("--alpha", type=float, default=1.0, help="ridge L2 penalty (default 1)")
    c.add_argument("--folds", type=int, default=5, help="stratified CV folds (default 5)")
    c.add_argument("--seed", type=int, default=0, help="seed for noise, subsets and folds")
    c.add_argument(
        "--jobs",
        type=int,
        default=os.cpu_count() or 1,
        help="worker processes (default: all cores)",
    )
    c.add_argument("--out", help="report folder (default reports/<dataset>)")
    c.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(func=run)


def parse_ranges(text: str) -> list[int]:
    """``"1-3,7"`` → ``[1, 2, 3, 7]``."""
    out: list[int] = []
    for part in text.split(","):
        part = part.strip()
        try:
            if "-" in part:
                lo, hi = (int(v) for v in part.split("-", 1))
                if hi < lo:
                    raise ValueError
                out.extend(range(lo, hi + 1))
            elif part:
                out.append(int(part))
        except ValueError:
            raise ValueError(f"bad range {part!r} in {text!r} (use e.g. 1-40 or 1,3,5-9)") from None
    if not out:
        raise ValueError(f"empty range {text!r}")
    return out


def encoder_overrides(settings: list[str], names: list[str]) -> dict[str, dict]:
    """Parse ``--set enc.param=value`` options into per-encoder keyword arguments."""
    from ..encoders import parse_setting

    out: dict[str, dict] = {n: {} for n in names}
    for item in settings:
        key, sep, value = item.partition("=")
        enc, dot, param = key.strip().partition(".")
        if not sep or not dot:
            raise ValueError(f"--set {item!r}: expected ENCODER.PARAM=VALUE, e.g. lif.gain=3000")
        try:
            out.setdefault(enc, {})[param] = parse_setting(enc, param, value)
        except ValueError as exc:
            raise ValueError(f"--set {item!r}: {exc}") from None
    return out


def tuned_encoder_settings(network: str, names: list[str]) -> dict[str, dict]:
    """Encoder settings from the ``[encoder]`` tables of the network files that ``network``
    (``{encoder}`` replaced by each name) gives each encoder of ``names``: ``{name: settings}``
    for the files tuned on that encoder; a file tuned on another encoder is noted on stderr."""
    from ..config import read_encoder_table

    out = {}
    for name in names:
        source = network.replace("{encoder}", name)
        table = read_encoder_table(source)
        if table is None:
            continue
        tuned_on, settings = table
        if tuned_on == name:
            out[name] = settings
            print(f"{name}: encoder settings from {source} [encoder]", file=sys.stderr)
        else:
            print(
                f"note: {source} was tuned on {tuned_on} spike trains; {name} keeps its own "
                "settings",
                file=sys.stderr,
            )
    return out


def load_samples(args):
    from ..datasets import DEFAULT_SAMPLE_DURATION, load_biotac, load_folder_dataset
    from ..datasets.synthetic import SYNTHETIC_DURATION, make_synthetic

    progress = not args.quiet
    duration = args.duration
    if duration is None:
        duration = SYNTHETIC_DURATION if args.dataset == "synthetic" else DEFAULT_SAMPLE_DURATION
    if args.dataset == "synthetic":
        samples = make_synthetic(
            args.synthetic_classes, args.synthetic_samples, duration, seed=args.seed
        )
    elif args.dataset == "biotac":
        root = args.data or os.environ.get(BIOTAC_ENV)
        if not root:
            raise ValueError(f"--dataset biotac needs --data PATH (or ${BIOTAC_ENV})")
        recordings = parse_ranges(args.recordings) if args.recordings else None
        samples = load_biotac(root, args.classes or "thesis11", recordings, duration, progress)
    else:
        if not args.data:
            raise ValueError("--dataset folder needs --data PATH")
        classes = [c.strip() for c in args.classes.split(",")] if args.classes else None
        samples = load_folder_dataset(
            args.data, args.fs, classes, duration=duration, progress=progress
        )
    if args.per_class:
        samples = samples.per_class(args.per_class, args.seed)
    return samples


def load_split(args):
    """``(training samples, held-out samples or None)``: :func:`load_samples` split by
    ``--test-recordings`` (BioTac recording numbers; refused for other datasets and when a class
    would have no recording on one side)."""
    import numpy as np

    samples = load_samples(args)
    if not getattr(args, "test_recordings", None):
        return samples, None
    if args.dataset != "biotac":
        raise ValueError("--test-recordings needs --dataset biotac (recording numbers)")
    from ..datasets.biotac import recording_numbers

    held = parse_ranges(args.test_recordings)
    mask = np.isin(recording_numbers(samples), held)
    if not mask.any():
        raise ValueError(f"--test-recordings {args.test_recordings}: none of the loaded "
                         "recordings (check --recordings)")  # fmt: skip
    return samples.split_by(mask)


def run(args: argparse.Namespace) -> int:
    from ..encoders import make_encoder
    from ..pipeline import PipelineConfig, run_pipeline
    from ..report import write_report
    from ..report.markdown import accuracy_table, percent

    names = [n.strip() for n in args.encoders.split(",") if n.strip()]
    overrides = encoder_overrides(args.set, names)
    features = tuple(f.strip() for f in args.features.split(",") if f.strip())
    tuned = tuned_encoder_settings(args.network, names) if "spll" in features else {}
    encoders = [make_encoder(n, **(tuned.get(n, {}) | overrides[n])) for n in names]
    config = PipelineConfig(
        features=features,
        phase_noise=args.phase_noise,
        repeats=args.repeats,
        seed=args.seed,
        n_splits=args.folds,
        alpha=args.alpha,
        isi_spacing=args.isi_spacing,
        network=args.network,
        backend=checked_backend(args.backend) if "spll" in features else "golden",
        jobs=max(1, args.jobs),
        progress=not args.quiet,
    )
    if "spll" in config.features:
        from ..config import NetworkConfig

        for name in names:  # reject a bad preset or file before the long run
            NetworkConfig.load(config.network_for(name)).build()
    samples, test = load_split(args)
    result = run_pipeline(samples, encoders, config, test)
    out = args.out or os.path.join("reports", samples.name)
    command = "spll-hw " + " ".join(shlex.quote(a) for a in sys.argv[1:]) if sys.argv[1:] else None
    summary = write_report(result, out, command)
    print(f"{samples.name}: {len(samples)} samples, {samples.n_classes} classes")
    for feature, row in accuracy_table(result).items():
        print(f"  {feature:8s} " + "  ".join(f"{enc}: {percent(*acc)}" for enc, acc in row.items()))
    print(f"report: {summary}")
    return 0
