"""Outputs: where the bytes go (files, devices, pipes, stdout) and the formats written there."""

from .targets import STDIO, AtomicFile, DirectFile, StdoutFile, is_direct, open_output, output_file

__all__ = ["STDIO", "AtomicFile", "DirectFile", "StdoutFile", "is_direct", "open_output", "output_file"]
