:- module(relrl_kbstate,
          [ kb_get/3,             % +KB, +Part, -Value
            kb_set/3,             % +KB, +Part, +Value
            kb_forget/1,          % +KB
            kb_record_exists/1    % ?KB
          ]).
:- use_module(library(error)).

/** <module> One state record per knowledge base

Everything the engine and its learners keep for a knowledge base between two calls lives
in one term, the knowledge base's record, in one global variable: its engine (the run and
the last step), working memory, the necessity units' outputs, the learner's own term, a
tree, the task a world learns, and the snapshots kept by engine_keep/2. kb_forget/1
deletes the record whole; what a learner keeps as clauses of its own module it removes in
its learner_forget/2 hook (engine.pl), so dropping a knowledge base leaves nothing of it.

A part is read with kb_get/3 and replaced with kb_set/3, which copies the value into the
record (nb_setarg/3): nothing stored depends on a binding that backtracking could undo. A
part may also be a live term its owner changes in place with nb_setarg/3 (the engine's
last step, a tree's nodes): kb_get/3 gives the stored term itself, not a copy.

The record is made at the first use of a knowledge base (a plain-swipl user may step
`user`); its global variable's name is made once and found afterwards by one clause look-up
(atom_concat/3 would look the atom up again at every call).
*/

:- dynamic key_/2.                  % KB, the name of its record's global variable

%   The parts of a record, by position.
part(engine, 1).                    % engine(Run, Prev, Random) or none (engine.pl)
part(memory, 2).                    % wm(Clock, Span, Pairs, Elements, Now) (memory.pl)
part(units, 3).                     % Necessity-Y pairs (motivation.pl)
part(learner, 4).                   % the learner's own term, or none
part(tree, 5).                      % a tree (qtree.pl, tg_tree.pl), or none
part(task, 6).                      % the task a world learns next (world.pl), or none
part(kept, 7).                      % Slot-Snapshot pairs (engine_keep/2)

empty(kb(none, wm(0, default, [], [], []), [], none, none, none, [])).

new_record(KB, Record) :-
    must_be(atom, KB),
    atom_concat('$relrl_kb:', KB, Key),
    empty(Empty),
    nb_setval(Key, Empty),
    assertz(key_(KB, Key)),
    nb_getval(Key, Record).

%!  kb_get(+KB, +Part, -Value) is det.
%
%   Value is the Part of KB's record (the stored term itself). A part never set has its
%   empty value: `none`, an empty memory, [] for the units and the kept snapshots.
%
%   (kb_get/3 and kb_set/3 look the record up themselves: they run some twenty times an
%   ETG step, and a predicate of its own for the look-up cost 20 of its ~450 inferences.)

kb_get(KB, Part, Value) :-
    (   key_(KB, Key)
    ->  nb_getval(Key, Record)
    ;   new_record(KB, Record)
    ),
    (   part(Part, I)
    ->  arg(I, Record, Value)
    ;   domain_error(kb_part, Part)
    ).

%!  kb_set(+KB, +Part, +Value) is det.
%
%   Part of KB's record becomes a copy of Value.

kb_set(KB, Part, Value) :-
    (   key_(KB, Key)
    ->  nb_getval(Key, Record)
    ;   new_record(KB, Record)
    ),
    (   part(Part, I)
    ->  nb_setarg(I, Record, Value)
    ;   domain_error(kb_part, Part)
    ).

%!  kb_forget(+KB) is det.
%
%   Delete KB's record and the name of its global variable.

kb_forget(KB) :-
    must_be(atom, KB),
    (   retract(key_(KB, Key))
    ->  nb_delete(Key)
    ;   true
    ).

%!  kb_record_exists(?KB) is nondet.
%
%   KB has a record (it was used and not forgotten).

kb_record_exists(KB) :-
    key_(KB, _).
