"""Behavioural cloning (issue 16), the training side: the expert recording (expert.py), log to
dataset (dataset.py), the one preprocessing of the model's sidecar (spec.py), balancing and
augmentation (augment.py), the network (model.py), training and export (train.py), analysis
(analyse.py) and the one command that makes the shipped model (make_model.py). Entry point:
tools/pilot (cli.py)."""
