"""FMU of a body tied by a torsional spring-damper to another body's port."""

from component_slave import ComponentSlave


class SpringDamperInertia(ComponentSlave):
    component = "rotational.SpringDamperInertia"
    # Scenes coupling it with other FMUs (its documentation lists their connections).
    examples = ("scenarios/two_inertias.toml",)
    description = "Body on a torsional spring-damper driven by another body's port motion"
    default_run = (0.0, 1.0, 1.0e-3)
