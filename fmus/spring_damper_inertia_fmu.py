"""FMU of a body tied by a torsional spring-damper to another body's port."""

from component_slave import ComponentSlave

from components.rotational import SpringDamperInertia as _Component


class SpringDamperInertia(ComponentSlave):
    component_class = _Component
    description = "Body on a torsional spring-damper driven by another body's port motion"
    default_run = (0.0, 1.0, 1.0e-3)
