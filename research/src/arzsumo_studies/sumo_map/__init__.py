"""What SUMO does on the network: where it holds a congested section (approach, fill), its
options, wave directions, the meter's dynamics and the open-loop runs and fits they
share.
"""
