"""FMU: Straight-sided verge runaway escapement of the M739 S&A."""

from component_slave import ComponentSlave

from components.verge_escapement import VergeEscapement as _Component


class VergeEscapement(ComponentSlave):
    component_class = _Component
    description = "Straight-sided verge runaway escapement of the M739 S&A"
    default_run = (0.0, 0.01, 1.0e-5)
