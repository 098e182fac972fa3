"""The PDE controllers' ablation in SUMO on the former default: its steps, what each did to
the meter and the section, the held ramp.
"""
