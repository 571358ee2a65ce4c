:- module(relrl_world_bias,
          [ world_bias_modes/2,   % +KB, -Modes
            world_bias_types/2    % +KB, -Types
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(declarations).

/** <module> A world's language bias generated from its declared types

A world that writes no rmode/1 may declare the argument types of its relations and actions
instead, and relrl generates tg's language bias from them (docs/worlds.md, *A bias from
declarations*):

    signature(on(block, place)).     % on/2: a block on a place (a relation of the view)
    signature(move(block, place)).   % move/2: an action (its name is an action/1 template's)
    subtype(block, place).           % every block is a place
    type(floor, place).              % floor is a constant, a place

A type with constants of its own (type/2) and no subtype is *enumerated* (directions,
north ... west); a type without constants or subtypes is a type of *objects*, the world's
blocks, cells, trucks, which the bias never names (b3 is a block like any other): a test
speaks of a variable. A type with subtypes is the union of theirs and its own constants.

Each argument of a relation's signature becomes, in a mode:

  - `+S` for every object type S the argument's type holds, and every enumerated type an
    action names: a variable bound earlier on the tree's path (the moved block, the
    direction of go(Dir));
  - `-S` for every object type S it holds: a new variable, bound by the test;
  - each constant of the type (`floor`, `parcel`), but not those of an enumerated type an
    action names (a test speaks of the direction the action takes, not of north).

A mode is kept when it is linked to the path (some `+`), names constants only (a test
of the state such as `here(parcel)` or `carried`), or names a constant of an enumerated
type beside its new variables (`at(-ball, rooma)`: some ball is still in room a, a fact of
one of the world's landmarks that an action without arguments, gripper's `move`, turns
on); any other mode with new variables and no `+` would ask whether the state holds such
facts at all ("some block is on some block", "some block is on the floor"), which tells
states near the goal from far ones and not a good action from a bad one. An action's signature gives
`action(...)` modes with `-S` for each object or enumerated type and the constants not of
an enumerated type (`move(-block, floor)`, `go(-dir)`). A
mode whose `+S` no kept mode can bind (no `-S` for it) is dropped. Relations without a
signature are in the learner's view but not in the bias.
*/

%!  world_bias_modes(+KB, -Modes:list) is det.
%
%   Modes are the rmode literals generated from KB's signature/1, subtype/2 and type/2
%   declarations, in the order of the signatures and, for each, of its arguments' options
%   (`+`, then `-`, then the constants); [] when KB declares no signature.

world_bias_modes(KB, Modes) :-
    must_be(atom, KB),
    findall(Sig, declared(KB, signature(Sig)), Sigs),
    world_bias_types(KB, Types),
    findall(Mode, ( member(Sig, Sigs), signature_mode(KB, Types, Sig, Mode) ), Modes0),
    list_to_set(Modes0, Modes1),
    bindable(Modes1, Modes).

%!  world_bias_types(+KB, -Types:list) is det.
%
%   Types are type(Name, VarTypes, Constants) terms, one per type KB's signatures name:
%   VarTypes the types of the variables an argument of that type may be (object and
%   enumerated types it holds), Constants the constants it holds (its own and its
%   subtypes').

world_bias_types(KB, Types) :-
    findall(T, ( declared(KB, signature(Sig)), compound(Sig), arg(_, Sig, T) ), Ts0),
    list_to_set(Ts0, Ts),
    maplist(type_info(KB), Ts, Types).

type_info(KB, T, type(T, VarTypes, Consts)) :-
    must_be(atom, T),
    sub_types(KB, T, [T], Below),
    findall(S, ( member(S, Below), var_type(KB, S) ), VarTypes),
    findall(C, ( member(S, Below), declared(KB, type(C, S)) ), Consts0),
    list_to_set(Consts0, Consts).

% Below: T and every type below it (subtype/2, transitively), T first.
sub_types(KB, T, Seen, Below) :-
    findall(S, ( declared(KB, subtype(S, T)), \+ memberchk(S, Seen) ), Direct),
    foldl(sub_types_of(KB), Direct, Seen, Seen1),
    (   Direct == []
    ->  Below = [T]
    ;   subtract(Seen1, Seen, New),
        Below = [T|New]
    ).

sub_types_of(KB, S, Seen0, Seen) :-
    sub_types(KB, S, [S|Seen0], Below),
    union(Seen0, Below, Seen).

% A type a variable may have: no subtypes (objects, or enumerated constants).
var_type(KB, S) :-
    \+ declared(KB, subtype(_, S)).

object_type(KB, S) :-
    var_type(KB, S),
    \+ declared(KB, type(_, S)).

signature_mode(KB, Types, Sig, Mode) :-
    (   atom(Sig)
    ->  Args = [], Name = Sig
    ;   compound_name_arguments(Sig, Name, Args)
    ),
    length(Args, N),
    (   action_name(KB, Name, N)
    ->  maplist(action_option(KB, Types), Args, Opts),
        compound_or_atom(Name, Opts, A),
        Mode = action(A)
    ;   maplist(relation_option(KB, Types), Args, Opts),
        linked_or_ground(KB, Opts),
        compound_or_atom(Name, Opts, Mode)
    ).

action_name(KB, Name, N) :-
    declared(KB, action(T)),
    callable(T),
    functor(T, Name, N),
    !.

compound_or_atom(Name, [], Name) :- !.
compound_or_atom(Name, Args, T) :-
    compound_name_arguments(T, Name, Args).

relation_option(KB, Types, T, Opt) :-
    memberchk(type(T, VarTypes, Consts), Types),
    (   member(S, VarTypes), bindable_type(KB, Types, S), Opt = +(S)
    ;   member(S, VarTypes), object_type(KB, S), Opt = -(S)
    ;   member(Opt, Consts),
        \+ ( member(S, VarTypes), declared(KB, type(Opt, S)), action_type(KB, S) )
    ).

% S may be bound by a test: a type of objects, or an enumerated type an action names.
bindable_type(KB, _, S) :-
    object_type(KB, S),
    !.
bindable_type(KB, _, S) :-
    action_type(KB, S).

% S is an enumerated type an action's signature names (go(dir)).
action_type(KB, S) :-
    declared(KB, signature(Sig)),
    compound(Sig),
    functor(Sig, Name, N),
    action_name(KB, Name, N),
    arg(_, Sig, S),
    !.

% An action's argument: a new variable of each variable type, and the constants that are
% not of an enumerated type (move(-block, floor); go(-dir), not go(north)).
action_option(KB, Types, T, Opt) :-
    memberchk(type(T, VarTypes, Consts), Types),
    (   member(S, VarTypes), Opt = -(S)
    ;   member(Opt, Consts),
        \+ ( member(S, VarTypes), declared(KB, type(Opt, S)) )
    ).

linked_or_ground(KB, Opts) :-
    (   memberchk(+(_), Opts)
    ->  true
    ;   \+ memberchk(-(_), Opts)
    ->  true
    ;   member(C, Opts),
        enumerated_constant(KB, C)
    ->  true
    ).

% C is a constant of an enumerated type (rooma of room, left of gripper; not floor, a place
% that blocks are too).
enumerated_constant(KB, C) :-
    atomic(C),
    declared(KB, type(C, S)),
    var_type(KB, S),
    !.

% The modes whose every +S some mode binds (a -S of a kept mode), to a fixpoint.
bindable(Modes0, Modes) :-
    include(bound_by(Modes0), Modes0, Modes1),
    (   Modes1 == Modes0
    ->  Modes = Modes0
    ;   bindable(Modes1, Modes)
    ).

bound_by(Modes, Mode) :-
    forall(mode_arg(Mode, +(S)),
           ( member(M, Modes), M \== Mode, mode_arg(M, -(S)) )).

mode_arg(action(A), Arg) :-
    !,
    compound(A),
    arg(_, A, Arg).
mode_arg(M, Arg) :-
    compound(M),
    arg(_, M, Arg).
