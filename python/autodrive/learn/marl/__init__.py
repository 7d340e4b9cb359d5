"""Multi-agent intersection traversal (issue 17, training side): the C core's binding (core),
the paper's PettingZoo environment (env), the shared-parameter vectorisation for
stable-baselines3 (vec), PPO training (train), ONNX export (export), the rule-based baseline
(baseline) and seeded evaluation (evaluate). Entry point: tools/marl {train,eval}."""
