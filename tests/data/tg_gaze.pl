/*  A small relational task for the tg learner's tests: a caregiver looks at one of four
    places; looking where it looks is rewarded at the next step (smell(treat)). One
    necessity, always active. The relational view is gaze(face, Place); the bias lets a
    test relate the action's place to the gaze's. */

stimulus(face).
stimulus(treat).
stimulus_property(treat, reinforcer).

% The propositional view (the state code of contingency, Q-learning and ETG): one fact per
% place the caregiver can look at.
fact(looks(p1)).
fact(looks(p2)).
fact(looks(p3)).
fact(looks(p4)).

looks(Place) :- memory(pose(face, Place), 0).

response(look(p1)).
response(look(p2)).
response(look(p3)).
response(look(p4)).

necessity(curiosity).
unit(curiosity, bias, 5.0).
unit(curiosity, recurrent_weight, 0.0).
unit(curiosity, delta, 0.0).
unit(curiosity, threshold, 0.5).

relation(gaze(_Who, _Place)).
relation(fed(_What)).

gaze(Who, Place) :- memory(pose(Who, Place), 0).
fed(What)        :- memory(smell(What), 0).

rmode(gaze(#agent, -place)).
rmode(gaze(#agent, #place)).
rmode(fed(#food)).
rmode(action(look(-place))).
rmode(action(look(+place))).

rconst(agent, face).
rconst(place, p1).
rconst(place, p2).
rconst(place, p3).
rconst(place, p4).
rconst(food, treat).
