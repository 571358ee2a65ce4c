/*  A small deterministic task for the learners' tests: two states (light, dark), three
    responses, one necessity that is always active. Pressing `a` in the light and `c` in
    the dark is rewarded; the reward is heard at the next step. */

stimulus(light).
stimulus(dark).
stimulus(food).

stimulus_property(food, reinforcer).

response(a).
response(b).
response(c).

necessity(hunger).
unit(hunger, bias, 5.0).
unit(hunger, recurrent_weight, 0.0).
unit(hunger, delta, 0.0).
unit(hunger, threshold, 0.5).
