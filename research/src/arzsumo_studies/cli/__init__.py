"""The command-line side of the studies that are library code: per study its options on
the command line (argparse) mapped onto the study's frozen ``Options``, its ``run`` called
with them, its result printed. The study itself (``arzsumo_studies.NAME``) holds no
argparse."""
