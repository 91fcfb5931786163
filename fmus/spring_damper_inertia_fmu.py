"""FMU of a body tied by a torsional spring-damper to another body's port."""

from component_slave import ComponentSlave


class SpringDamperInertia(ComponentSlave):
    component = "rotational.SpringDamperInertia"
    description = "Body on a torsional spring-damper driven by another body's port motion"
    default_run = (0.0, 1.0, 1.0e-3)
