/*  Experiment 2 of da Silva & Romero (2012), section 5.2: a robotic head, a caregiver and
    three fruits (apple, lemon, orange). The robot learns to follow the caregiver's gaze to
    the fruit and then to name it (declarative pointing).

    Load it with relrl (relrl check examples/domains/fruits.pl) or in plain SWI-Prolog:
        swipl prolog/relrl.pl examples/domains/fruits.pl

    Places the head can look at: centre (the caregiver), left, left_down, down, right_down,
    right. Percepts come from perception: see(face), pose(face, Pose), see(object),
    colour(object, Colour), at(object, Place), at(Place) (where the head looks),
    hear(attention), hear(Word).
*/

% ---- Stimuli -----------------------------------------------------------------------------

stimulus(face).
stimulus(object).
stimulus(attention).
stimulus(environment).

stimulus_property(attention, reinforcer).

% ---- Facts -------------------------------------------------------------------------------

% Red, orange and green objects are fruits.
fact(red_fruit(object)).
fact(orange_fruit(object)).
fact(green_fruit(object)).

% The caregiver's head pose: frontal, two left profiles, two right profiles, down.
fact(frontal(face)).
fact(left_profile_1(face)).
fact(left_profile_2(face)).
fact(right_profile_1(face)).
fact(right_profile_2(face)).
fact(down_profile(face)).

% What the robot is focusing: the caregiver, or a fruit.
fact(looking_frontal(face)).
fact(looking_fruit(object)).

red_fruit(object)    :- see(object), percept(colour(object, red)).
orange_fruit(object) :- see(object), percept(colour(object, orange)).
green_fruit(object)  :- see(object), percept(colour(object, green)).

frontal(face)         :- percept(pose(face, frontal)).
left_profile_1(face)  :- percept(pose(face, left_1)).
left_profile_2(face)  :- percept(pose(face, left_2)).
right_profile_1(face) :- percept(pose(face, right_1)).
right_profile_2(face) :- percept(pose(face, right_2)).
down_profile(face)    :- percept(pose(face, down)).

looking_frontal(face) :- at(centre), see(face).
looking_fruit(object) :-
    see(object),
    (   red_fruit(object)
    ;   orange_fruit(object)
    ;   green_fruit(object)
    ),
    !.

% ---- The relational view (learner tg) ----------------------------------------------------

% What the robot perceives now, as relations over agents, places, objects, colours and
% words. Their ground solutions are the relational state the tg learner learns from (the
% state code above is unchanged for the other learners).
relation(sees(_Thing)).
relation(gaze(_Who, _Place)).
relation(head_at(_Place)).
relation(object_at(_Object, _Place)).
relation(colour(_Object, _Colour)).
relation(heard(_Word)).

sees(Thing)              :- memory(see(Thing), 0).
gaze(Who, Place)         :- memory(pose(Who, Pose), 0), pose_place(Pose, Place).
head_at(Place)           :- memory(at(Place), 0).
object_at(Object, Place) :- memory(at(Object, Place), 0).
colour(Object, Colour)   :- memory(colour(Object, Colour), 0).
heard(Word)              :- memory(hear(Word), 0).

% Where a head pose points (perception's pose classes): a frontal face looks at the robot
% (centre), a strong turn to the left of the image at left, a slight one at left_down.
pose_place(frontal, centre).
pose_place(left_2, left).
pose_place(left_1, left_down).
pose_place(down, down).
pose_place(right_1, right_down).
pose_place(right_2, right).

% ---- The language bias (learner tg) ------------------------------------------------------

% Single literals with modes: +T a variable of type T bound earlier on the path (or by the
% action), -T a new variable, #T each constant of type T. See docs/tg.md. Places, objects
% and colours enter tests only as variables; the caregiver's face (centre) and the words
% the caregiver says are the task's own constants.
rmode(sees(#thing)).
rmode(gaze(#agent, -place)).
rmode(gaze(#agent, +place)).
rmode(gaze(#agent, #face_place)).
rmode(head_at(+place)).
rmode(head_at(#face_place)).
rmode(object_at(-object, -place)).
rmode(object_at(-object, +place)).
rmode(colour(+object, -colour)).
rmode(colour(+object, +colour)).
rmode(heard(#word)).
rmode(action(look(-place))).
rmode(action(look(+place))).
rmode(action(look(#face_place))).
rmode(action(name_object)).
rmode(necessity(#necessity)).

rconst(thing, face).
rconst(thing, object).
rconst(thing, environment).
rconst(agent, face).
rconst(face_place, centre).
rconst(word, attention).
rconst(word, apple).
rconst(word, orange).
rconst(word, lemon).
rconst(word, lime).

% ---- Responses ---------------------------------------------------------------------------

% Look at the caregiver or search one of the five regions; name the object in view.
response(look(centre)).
response(look(left)).
response(look(left_down)).
response(look(down)).
response(look(right_down)).
response(look(right)).
response(name_object).

% ---- Constraint rules --------------------------------------------------------------------

% Nothing to name when no object is in view.
forbidden(name_object) :- \+ see(object).

% ---- Necessities -------------------------------------------------------------------------

% socialize, with the parameters of section 5.2 (relrl_domains(socialize) is
% examples/domains/socialize.pl). The paper's input weights are positive magnitudes;
% declared as satisfiers they enter Eq. 1 negated, so contact lowers the need (see
% docs/engine.md for the sign convention).
:- include(relrl_domains(socialize)).

satisfier(socialize, hear(attention), 1.50).
satisfier(socialize, see(frontal(face)), 0.95).
satisfier(socialize, see(looking_frontal(face)), 0.50).
satisfier(socialize, see(looking_fruit(object)), 1.50).

% ---- Behaviour rules ---------------------------------------------------------------------

% An innate preference: when the caregiver's face is in view, look at it.
behaviour(see(face), look(centre), socialize, 2.0).
