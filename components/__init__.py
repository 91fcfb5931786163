"""Physics of the mechanical subsystems: plain Python, SI units, no FMI imports."""
