/*  A relational task with many places for the tg learner's tests of classes of responses:
    a caregiver at `home` looks at one of twelve places and a toy may lie at one; the robot
    looks at home or at a place. Places enter the bias only as variables; home is the one
    place constant. */

stimulus(face).
stimulus(treat).
stimulus_property(treat, reinforcer).

response(look(home)).
response(look(p1)).
response(look(p2)).
response(look(p3)).
response(look(p4)).
response(look(p5)).
response(look(p6)).
response(look(p7)).
response(look(p8)).
response(look(p9)).
response(look(p10)).
response(look(p11)).
response(look(p12)).
response(wait).

necessity(curiosity).
unit(curiosity, bias, 5.0).
unit(curiosity, recurrent_weight, 0.0).
unit(curiosity, delta, 0.0).
unit(curiosity, threshold, 0.5).

relation(gaze(_Who, _Place)).
relation(toy_at(_Toy, _Place)).
relation(fed(_What)).

gaze(Who, Place)   :- memory(pose(Who, Place), 0).
toy_at(Toy, Place) :- memory(at(Toy, Place), 0).
fed(What)          :- memory(smell(What), 0).

rmode(gaze(#agent, -place)).
rmode(gaze(#agent, #home)).
rmode(toy_at(-toy, -place)).
rmode(toy_at(-toy, +place)).
rmode(fed(#food)).
rmode(action(look(-place))).
rmode(action(look(+place))).
rmode(action(look(#home))).
rmode(action(wait)).

rconst(agent, face).
rconst(home, home).
rconst(food, treat).
