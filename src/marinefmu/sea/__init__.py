"""The truth side: waves, vessel response and sensor models. Never imports an estimator."""
