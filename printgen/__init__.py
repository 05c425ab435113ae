"""printgen: stiffness-scaled, printable flexible-barrier models for flume experiments.

Based on Lambert et al., "Small-Scale Modeling of Flexible Barriers. I: Mechanical Similitude
of the Structure", J. Hydraul. Eng. 149(3), 2023, doi:10.1061/JHEND8.HYENG-13070.
"""

__version__ = "0.1.0"
