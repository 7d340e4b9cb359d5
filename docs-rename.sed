# Issue 42, docs: the README became a site (mkdocs.yml, docs/). Rewrites what other files cite:
# the generated pages that moved into docs/reference/, and comments that send the reader to a
# README section, now a site page. Apply after merging (GNU sed, ERE), e.g.
#   git grep -lE 'CHANNELS\.md|VEHICLE\.md|README' -- python tests tools | xargs sed -i -E -f docs-rename.sed
# Idempotent: no replacement matches a pattern again.
# ---- generated pages, now site pages -------------------------------------------------------
s#lcm_types/CHANNELS\.md#docs/reference/channels.md#g
s#docs/VEHICLE\.md#docs/reference/vehicle.md#g
s#CHANNELS\.md#docs/reference/channels.md#g
# ---- README sections cited in comments and help texts ---------------------------------------
s#\(README, Behavioural cloning\)#(docs/guides/training.md)#g
s#; README, "Behavioural cloning":#; docs/guides/training.md:#g
s#a label the picture determines; README\)#a label the picture determines; docs/guides/training.md)#g
s#\(README: the reverse direction\)#(docs/guides/demo-cloning.md: the reverse direction)#g
s#\(README, issue 16\)#(docs/guides/training.md)#g
s#enough for 3 laps, README\)#enough for 3 laps, docs/results/smart-city.md)#g
s#\(README, smart-city section:#(docs/results/smart-city.md:#g
s#a Ray cluster of lab machines: README, #a Ray cluster of lab machines: docs/guides/sweeps.md, #g
s#Goals of issue 7 \(runtime/jetson/(modules/)?autonomy/README\.md\)#The parking goals (docs/results/parking.md)#g
s#goals are measured by full runs, see README\)#goals are measured by full runs, see docs/results/smart-city.md)#g
s#\(tools/setup adds one; README\.md, "Tests"\)#(tools/setup adds one; docs/guides/tests.md)#g
s#0\.5 px off OpenCV's \(eye/README\.md\)#0.5 px off OpenCV's (docs/reference/eye.md)#g
s#\(docs/ARCHITECTURE\.md, Clocks\)#(docs/design/clocks.md)#g
