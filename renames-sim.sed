# Renames of issue 42's simulator split (branch redesign-sim). Apply to C/C++/Python/Markdown
# that names the simulator's modules: sed -i -E -f renames-sim.sed FILE...
# publish queue (was lcmq: "LCM queue")
s/\blcmq_t\b/publish_queue_t/g
s/\bstruct lcmq\b/struct publish_queue/g
s/\blcmq_/publish_queue_/g
s/\blcmq\.(h|c)\b/publish_queue.\1/g
s/\bSIM_LCMQ_H\b/SIM_PUBLISH_QUEUE_H/g
# the program's LCM publishers (was lcmpub)
s/\blcmpub_truth\b/publish_ground_truth/g
s/\blcmpub_clock\b/publish_sim_clock/g
s/\blcmpub_lidar\b/publish_lidar_scan/g
s/\blcmpub\.(h|c)\b/lcm_publish.\1/g
s/\bSIM_LCMPUB_H\b/SIM_LCM_PUBLISH_H/g
# traffic lights on LCM (was tl_lcm)
s/\btl_lcm_t\b/traffic_lights_lcm_t/g
s/\bstruct tl_lcm\b/struct traffic_lights_lcm/g
s/\btl_lcm_/traffic_lights_lcm_/g
s/\bTL_LCM_/TRAFFIC_LIGHTS_LCM_/g
s/\btl_lcm\.(h|c)\b/traffic_lights_lcm.\1/g
s/\bSIM_TL_LCM_H\b/SIM_TRAFFIC_LIGHTS_LCM_H/g
# the vehicle description loader (was vparams, prefix vp_)
s/\bvp_params_t\b/vehicle_params_t/g
s/\bstruct vp_params\b/struct vehicle_params/g
s/\bvp_([a-z_]+)/vehicle_params_\1/g
s/\bvparams\.(h|c)\b/vehicle_params.\1/g
s/\bSIM_VPARAMS_H\b/SIM_VEHICLE_PARAMS_H/g
# the LCM receive filter (was lcm_rxfilter, prefix lcmrx_)
s/\blcmrx_keep_only\b/lcm_receive_filter_keep_only/g
s/\blcm_rxfilter\.(h|c)\b/lcm_receive_filter.\1/g
s/\bSIM_LCM_RXFILTER_H\b/SIM_LCM_RECEIVE_FILTER_H/g
# the scene generator (was mg_) and the footprint clearance checks (was cl_)
s/\bmg_options_t\b/mjcf_gen_options_t/g
s/\bstruct mg_options\b/struct mjcf_gen_options/g
s/\bmg_(write_scene|write_physics_map|tag_id|car|geom_named|late_box|rel_from)\b/mjcf_gen_\1/g
s/\bcl_prism_t\b/clearance_prism_t/g
s/\bstruct cl_prism\b/struct clearance_prism/g
s/\bcl_(check_on_map|corners|geom_prism|name|on_plane|prisms_overlap|radius)\b/clearance_\1/g
s/\bCL_(UPRIGHT_COS|VERTICAL_NZ|EPS_M)\b/CLEARANCE_\1/g
