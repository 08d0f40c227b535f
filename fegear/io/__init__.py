"""Writers of results: JSON summary, VTK for ParaView, PNG pictures."""

from fegear.io.hertz_output import write_hertz_outputs

__all__ = ["write_hertz_outputs"]
