"""Face-milled bevel gears generated on a cradle: blank, head cutter, machine, synthesis, members.

The modules follow the making of the gear: :mod:`.blank` (pitch cones, proportions, flank
coordinates; a hypoid's pitch cones :mod:`.hypoid_cones` and blank :mod:`.hypoid`),
:mod:`.cutter` (the head cutter's blades and edge radii), :mod:`.machine` (the machine settings
and the generating motion), :mod:`.synthesis` (settings from design targets), :mod:`.mesh_frame`
(where the pair sits), :mod:`.member` and :mod:`.native` (the generated flanks and fillets, exact
and fast), :mod:`.pair` (the designed pair). Sources: Litvin &
Fuentes, *Gear Geometry and Applied Theory*, 2nd ed., 2004, ch. 9 and 21; Litvin & Zhang, NASA
CR-4342 (1991); Argyris, Fuentes & Litvin, CMAME 191 (2002) 1057–1095.
"""

from .blank import SpiralBevelBlank
from .hypoid import HypoidBlank
from .machine import MachineSettings, SpiralBevelSettings
from .member import SpiralBevelMember
from .pair import SpiralBevelPair, transmission_error
from .synthesis import SynthesisReport, SynthesisTargets

__all__ = [
    "HypoidBlank",
    "MachineSettings",
    "SpiralBevelBlank",
    "SpiralBevelMember",
    "SpiralBevelPair",
    "SpiralBevelSettings",
    "SynthesisReport",
    "SynthesisTargets",
    "transmission_error",
]
