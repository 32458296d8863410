"""``spll-hw export``: write a network for another toolchain (the targets registered in
:mod:`spll_hw.exporters`: Lava processes, a NIR graph), check what was written against the
golden model (:mod:`spll_hw.exporters.check`; a check the exporter already ran from memory on
what it wrote counts where it is the same check, :func:`spll_hw.exporters.export_checked`), and
put the folder in place only when both are done (:func:`spll_hw.files.atomic_folder`). With
a multichannel ``--network``: ``--to nir``, the network and its trained spiking readout as one
NIR graph (:mod:`mappings.nir.multichannel`); ``--to nir-standard``, each channel group's
network exported and checked on its channels' encoded signals, and the readout as a graph of
standard nodes (:mod:`mappings.nir.multichannel_standard`).

An export never mixes with another: an ``--out`` that holds an export is replaced as a whole
(renamed aside, the new folder renamed into place), and one that holds anything else no export
writes is refused before any work (:func:`spll_hw.exporters.check_out_folder`).
``--check FOLDER`` never writes into FOLDER: the folder's own ``check.json`` and README stay
those of its export however the new check comes out (a stricter ``--max-error``, say); the
verdict is printed, and ``--out DIR`` gets the new check's record. A ``--max-error`` below
golden's own resolution on the check's inputs is refused before the check runs
(:func:`spll_hw.exporters.dt_ladder.refuse_unjudgeable_check`), but for a folder that golden
itself runs (``--to nir``)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ... import exporters
from ...exporters import check_limit
from ...exporters.check_files import read_network as read_exported_network
from ...exporters.check_files import stored_duration, stored_inputs, stored_target, write_check
from ...exporters.check_inputs import DURATION, user_input
from ...exporters.checked_folder import CheckFailed, ExportOptions, export_into, verdict
from ...exporters.cost import write_cost
from ...exporters.dt_ladder import refuse_unjudgeable_check
from ...exporters.encoded import encoded_inputs
from ...exporters.folder_check import check_folder
from ...files import atomic_folder
from ...multichannel.chips import whole_network
from ...multichannel.config import MultichannelConfig
from ...multichannel.readout_file import load_readout
from ..export import DEFAULT_OUT
from ..inputs import is_multichannel, read_network, read_spike_file


def run(args: argparse.Namespace) -> int:
    if args.check is None and args.out is None:
        args.out = DEFAULT_OUT
    if is_multichannel(args.network):
        return _export_multichannel(args)
    if args.readout is not None or args.threshold is not None:
        raise ValueError("--readout and --threshold need a multichannel --network FILE|PRESET")
    if args.check is not None:
        return _check_again(args)
    if args.to is None:
        raise ValueError("needs --to TARGET (or --check FOLDER to check an export again)")

    export = exporters.get(args.to)
    exporters.check_out_folder(args.out)  # before any work: nothing but an export is replaced
    network_file = read_network(args)
    config = network_file.config
    network = config.build()
    inputs = [*_user_inputs(args.check_input),
              *encoded_inputs(network_file, args.data, args.check_duration)]  # fmt: skip
    unwritten = (f". Nothing was written to {args.out}; --allow-error writes it anyway (its "
                 "README then says so at the top)")  # fmt: skip
    try:
        with atomic_folder(args.out, whole=True) as stage:
            done = export_into(export, args.to, config, stage, inputs, _options(args), unwritten)
    except KeyboardInterrupt:
        raise KeyboardInterrupt(f"nothing was written to {args.out}") from None
    report = done.report
    print(f"{network.n_spll} sPLLs ({config.layout}) exported to {args.to}:")
    for path in (args.out / p.relative_to(stage) for p in done.files):
        print(f"  {path}")
    print(verdict(report))
    consumers = getattr(export, "consumers", None)  # nir-standard: who runs it, and why not
    if consumers is not None:
        print(consumers(args.out), end="")
    return 0


def _export_multichannel(args: argparse.Namespace) -> int:
    """A multichannel ``--network FILE [--readout FILE --threshold THETA]``: the network and
    its trained readout, written by the target's multichannel writer
    (:func:`~spll_hw.exporters.exports_multichannel`; ``--to nir``: one NIR graph,
    :mod:`mappings.nir.multichannel`, read back once written; ``--to nir-standard``: a checked
    export per channel group and the readout's graph, :mod:`mappings.nir.multichannel_standard`)
    or nothing is written."""
    if args.out is None:
        raise ValueError("a multichannel --network cannot be checked again: drop --check")
    export_multichannel = exporters.multichannel_writer(args.to)
    exporters.check_out_folder(args.out)  # before any work: nothing but an export is replaced
    if args.check is not None or args.check_input or args.profile:
        raise ValueError("a multichannel --network: drop --check, --check-input and --profiles")
    if (args.readout is None) != (args.threshold is None):
        raise ValueError("--readout FILE and --threshold THETA go together")
    config = MultichannelConfig.load(args.network)
    saved = None if args.readout is None else load_readout(args.readout)
    if saved is not None and not args.allow_error:
        saved.check_loss(f"--readout {args.readout}")
    threshold = float("inf") if args.threshold is None else args.threshold
    files = export_multichannel(config, args.out, saved, threshold, data=args.data,
                                options=_options(args))  # fmt: skip
    network, _ = whole_network(config)
    what = "" if saved is None else f" and a {len(saved.readout.class_names)}-class readout"
    print(f"{network.n_spll} sPLLs of {len(config.channels)} channels{what} exported to "
          f"{args.to} (how each part was checked: {Path(args.out) / 'README.md'}):")  # fmt: skip
    for path in files:
        print(f"  {path}")
    return 0


def _check_again(args: argparse.Namespace) -> int:
    """``--check FOLDER [--out DIR]``: the folder's check run again, its verdict printed; the
    folder is only read (its own ``check.json`` and README stay those of its export, however
    this check comes out), and ``--out DIR`` gets this check's record (:func:`write_check`'s
    files and ``cost.json``, written whole). A limit no check of the folder can judge is
    refused before the check, with nothing written (module docstring)."""
    folder = args.check
    if args.dt is not None or args.profile is not None:
        raise ValueError("--check checks FOLDER as it was exported: drop --dt and --profiles")
    if not folder.is_dir():
        raise FileNotFoundError(f"--check {folder}: no such folder")
    out = args.out
    if out is not None:
        if out.resolve() == folder.resolve() or out.resolve().is_relative_to(folder.resolve()):
            raise ValueError(
                f"--out {out}: --check never writes into the folder it checks ({folder} keeps "
                "its own check); give another folder for this check's record"
            )
        exporters.check_out_folder(out)
    target = stored_target(folder)
    if target is None and args.to is None:
        raise ValueError(f"--check {folder}: no check.json says which target wrote it; pass --to")
    if target is not None and args.to is not None and args.to != target:
        raise ValueError(f"--check {folder}: its check.json says target {target}, not {args.to}")
    target = target or args.to
    inputs = [*stored_inputs(folder), *_user_inputs(args.check_input)]
    duration = args.check_duration or stored_duration(folder) or DURATION
    network = read_exported_network(folder)
    if not getattr(exporters.get(target), "runs_golden", False):  # golden judges any limit
        refuse_unjudgeable_check(folder, target, network, check_limit(args.max_error), duration,
                                 inputs)  # fmt: skip
    report = check_folder(folder, target, network, inputs=inputs, max_error=args.max_error,
                          allowed=args.allow_error, duration=duration,
                          max_failed=args.max_failed_splls)  # fmt: skip
    if out is not None:
        with atomic_folder(out, whole=True) as stage:
            write_check(stage, report, title=f"Check of `{folder}` again ({target})")
            write_cost(folder, target, network, report, into=stage)
    kept = f"{folder} unchanged" + (f"; this check in {out}" if out is not None else "")
    print(f"{folder} ({target}): {verdict(report)} ({kept})")
    if not report.passed and not args.allow_error:
        raise CheckFailed(f"{report.failure().rstrip('.')} ({kept})")
    return 0


def _options(args: argparse.Namespace):
    """The export's and its check's options from the command line."""
    return ExportOptions(args.profile, args.dt, args.max_error, args.allow_error,
                         args.check_duration, args.max_failed_splls)  # fmt: skip


def _user_inputs(paths: list[Path]) -> list:
    return [user_input(str(path), read_spike_file(path)) for path in paths]
