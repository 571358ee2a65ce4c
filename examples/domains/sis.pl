/*  The Social Interactive Simulator of Experiment 1 (da Silva & Romero 2012, section 5.1;
    after Triesch et al. 2006): a caregiver and the robot face to face, up to two toys.

    Load it with relrl (relrl check examples/domains/sis.pl) or in plain SWI-Prolog:
        swipl prolog/relrl.pl examples/domains/sis.pl

    Places: centre (the caregiver's face), left, left_down, down, right_down, right.
    The robot perceives only what is in its focus: the caregiver's face with the direction
    of the caregiver's gaze as pose(face, Place) (`frontal` when the caregiver looks at the
    robot), a toy at(toy, Place), or nothing (see(environment)); at(Place) is where its own
    head points. hear(attention) is the caregiver's attention, the reinforcer.
*/

% ---- Stimuli -----------------------------------------------------------------------------

stimulus(face).
stimulus(toy).
stimulus(attention).
stimulus(environment).

stimulus_property(attention, reinforcer).
stimulus_property(toy, graspable).

% ---- Facts -------------------------------------------------------------------------------

% Where the caregiver looks (the face's head pose), where the robot's head points, and
% where the robot has seen a toy (recently, see memory_span/1).
fact(gaze_frontal(face)).
fact(gaze_left(face)).
fact(gaze_left_down(face)).
fact(gaze_down(face)).
fact(gaze_right_down(face)).
fact(gaze_right(face)).
fact(head_at(centre)).
fact(head_at(left)).
fact(head_at(left_down)).
fact(head_at(down)).
fact(head_at(right_down)).
fact(head_at(right)).
fact(toy_at(left)).
fact(toy_at(left_down)).
fact(toy_at(down)).
fact(toy_at(right_down)).
fact(toy_at(right)).
fact(red_toy(toy)).
fact(green_toy(toy)).

gaze_frontal(face)    :- percept(pose(face, frontal)).
gaze_left(face)       :- percept(pose(face, left)).
gaze_left_down(face)  :- percept(pose(face, left_down)).
gaze_down(face)       :- percept(pose(face, down)).
gaze_right_down(face) :- percept(pose(face, right_down)).
gaze_right(face)      :- percept(pose(face, right)).

% Where the robot's head points now (age 0: this step's percept).
head_at(Place) :- memory(at(Place), 0).

% Where the robot has seen a toy, now or at the previous step.
toy_at(Place) :- at(toy, Place).

% The colour of the toy in view.
red_toy(toy)   :- see(toy), percept(colour(toy, red)).
green_toy(toy) :- see(toy), percept(colour(toy, green)).

% A percept stays in working memory for this many further steps.
memory_span(1).

% ---- The relational view (learner tg) ----------------------------------------------------

% What the robot perceives now, as relations over agents, places, toys, colours and words.
% The ground solutions of these templates are the relational state the tg learner learns
% from (the state code above is unchanged for the other learners).
relation(sees(_Thing)).
relation(gaze(_Who, _Place)).
relation(head_at(_Place)).
relation(toy_at(_Toy, _Place)).
relation(colour(_Toy, _Colour)).
relation(heard(_Word)).

sees(Thing)           :- memory(see(Thing), 0).
gaze(Who, Place)      :- memory(pose(Who, Pose), 0), pose_place(Pose, Place).
toy_at(Toy, Place)    :- memory(at(Toy, Place), 0).
colour(Toy, Colour)   :- memory(colour(Toy, Colour), 0).
heard(Word)           :- memory(hear(Word), 0).
% head_at(Place) is defined above.

% Where a face's pose points: a frontal face looks at the robot, whose place is centre.
pose_place(frontal, centre).
pose_place(left, left).
pose_place(left_down, left_down).
pose_place(down, down).
pose_place(right_down, right_down).
pose_place(right, right).

% ---- The language bias (learner tg) ------------------------------------------------------

% Single literals with modes: +T a variable of type T bound earlier on the path (or by the
% action), -T a new variable, #T each constant of type T. Conjunctions come from the
% refinement operator; see docs/tg.md. Places, toys and colours enter tests only as
% variables, so one test covers every place and the candidate tests do not grow with the
% world; the one place the task distinguishes, the caregiver's face (centre: where the
% robot looks to meet the caregiver's eyes, and where a caregiver looking at the robot
% looks), is a constant of its own type.
rmode(sees(#thing)).
rmode(gaze(#agent, -place)).
rmode(gaze(#agent, +place)).
rmode(gaze(#agent, #face_place)).
rmode(head_at(+place)).
rmode(head_at(#face_place)).
rmode(toy_at(-toy, -place)).
rmode(toy_at(-toy, +place)).
rmode(colour(+toy, -colour)).
rmode(colour(+toy, +colour)).
rmode(heard(#word)).
rmode(action(look(-place))).
rmode(action(look(+place))).
rmode(action(look(#face_place))).
rmode(necessity(#necessity)).

rconst(thing, face).
rconst(thing, toy).
rconst(thing, environment).
rconst(agent, face).
rconst(face_place, centre).
rconst(word, attention).

% ---- Responses ---------------------------------------------------------------------------

response(look(centre)).
response(look(left)).
response(look(left_down)).
response(look(down)).
response(look(right_down)).
response(look(right)).

% ---- Necessities -------------------------------------------------------------------------

necessity(socialize).
unit(socialize, bias, 1.00).
unit(socialize, recurrent_weight, 1.00).
unit(socialize, delta, 0.20).
unit(socialize, threshold, 0.50).

satisfier(socialize, hear(attention), 1.50).
satisfier(socialize, see(gaze_frontal(face)), 0.95).
satisfier(socialize, see(face), 0.50).

% ---- Behaviour rules ---------------------------------------------------------------------

behaviour(see(face), look(centre), socialize, 1.0).
