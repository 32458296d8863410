"""``spll-hw export``: write a network for another toolchain (Lava processes or a NIR graph)."""

from __future__ import annotations

import argparse
from pathlib import Path

from .common import add_params_argument, load_network_config

#: Export targets and what each writes.
TARGETS = {
    "lava": "lava.json + lava_<tag>.npz: Lava process parameters (float and fixed point), "
    "quantization.md",
    "nir": "network.nir: NIR graph (HDF5)",
}


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export",
        help="export a network as Lava processes or a NIR graph",
        description="Write the network of --params for another toolchain: Lava processes "
        "(floating-point and Loihi-2-like fixed-point parameters; load them with "
        "mappings.lava.load_export) or a NIR graph (read it with mappings.nir.read_nir). The "
        "folder also gets the network as params.toml.",
    )
    p.add_argument("--to", required=True, choices=sorted(TARGETS),
                   help="; ".join(f"{k}: {v}" for k, v in TARGETS.items()))  # fmt: skip
    add_params_argument(p)
    p.add_argument("--profile", default="loihi2",
                   help="quantize fixed-point profile for --to lava (default loihi2)")  # fmt: skip
    p.add_argument("--dt", type=float, help="time step [s] for --to lava (default: the profile's)")
    p.add_argument("--out", type=Path, required=True, help="output folder")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    config = load_network_config(args)
    network = config.build()
    out: Path = args.out
    if args.to == "nir":
        from mappings.nir import write_nir

        out.mkdir(parents=True, exist_ok=True)
        files = [write_nir(network, out / "network.nir")]
    else:
        import quantize
        from mappings.lava import export_lava

        files = export_lava(network, out, dt=args.dt, profile=args.profile)
        profile = quantize.load_profile(args.profile)
        q = quantize.quantize(network, profile if args.dt is None else profile.with_dt(args.dt))
        files.append(out / "quantization.md")
        files[-1].write_text(f"# {args.params} under {q.profile.name}\n\n{q.report_markdown()}\n")
    files.append(out / "params.toml")
    files[-1].write_text(config.to_toml())
    print(f"{network.n_spll} sPLLs ({config.layout}) exported to {args.to}:")
    for path in files:
        print(f"  {path}")
    return 0
