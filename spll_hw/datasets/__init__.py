"""Datasets as fixed-length, labelled, single-channel pressure samples (thesis 2.1).

- :func:`load_biotac`: BioTac_slide_20_50 (2.2 kHz PAC channel; 20 materials, the thesis's 11).
- :func:`load_folder_dataset`: VibTac-style folder-per-class WAV/CSV/NPY recordings.
- :func:`make_synthetic`: embedded synthetic textures, no download needed.

All return a :class:`SampleSet`.
"""

from .biotac import BIOTAC_FS, MATERIALS, THESIS_11, load_biotac, read_biotac_csv
from .samples import DEFAULT_SAMPLE_DURATION, SampleSet, split_recording
from .synthetic import make_synthetic
from .vibtac import load_folder_dataset, read_recording

__all__ = [
    "BIOTAC_FS",
    "DEFAULT_SAMPLE_DURATION",
    "MATERIALS",
    "THESIS_11",
    "SampleSet",
    "load_biotac",
    "load_folder_dataset",
    "make_synthetic",
    "read_biotac_csv",
    "read_recording",
    "split_recording",
]
