"""OpenDRIVE road networks in and out of the kit's map format (tools/map import / export), and
a first OpenSCENARIO subset (scenario.py). xodr.py reads a file strictly, reference_line.py and
lanes.py sample its geometry (our own sampler, checked against pyxodr), network.py turns driving
lanes into the kit's lanes and routes, importer.py writes the map, exporter.py writes ours."""
