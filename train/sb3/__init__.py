"""``bearing-env train`` and ``bearing-env hyperparams``: stable-baselines3 training with
rl-zoo3 hyperparameter files (the command line in :mod:`~bearing_env.train.sb3.train_cli`)."""
