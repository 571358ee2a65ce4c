:- module(relrl_kbstate,
          [ kb_record/2,          % +KB, -Record
            record_get/3,         % +Record, +Part, -Value
            record_set/3,         % +Record, +Part, +Value
            kb_get/3,             % +KB, +Part, -Value
            kb_set/3,             % +KB, +Part, +Value
            kb_nest/3,            % +Owner, +Key, +Options
            kb_forget/1,          % +KB
            kb_record_exists/1    % ?KB
          ]).
:- use_module(library(error)).

/** <module> One state record per knowledge base

Everything the engine and its learners keep for a knowledge base between two calls lives
in one term, the knowledge base's record, in one global variable: its engine (the run and
the last step), working memory, the necessity units' outputs, the learner's own term, a
tree, the task a world learns, the snapshots kept by engine_keep/2, and a second record
kept inside this one for a learner with a second tree (ptg's P-tree: kb_nest/3).
kb_forget/1 deletes the record whole, the record inside it with it; what a learner keeps as clauses of its own module it removes in
its learner_forget/2 hook (engine.pl), so dropping a knowledge base leaves nothing of it.

kb_record/2 finds the record of a knowledge base; record_get/3 reads a part of it and
record_set/3 replaces one with a copy of the value (nb_setarg/3): nothing stored depends on
a binding that backtracking could undo. A part may also be a live term its owner changes in
place with nb_setarg/3 (the engine's last step, a tree's nodes): record_get/3 gives the
stored term itself, not a copy. kb_get/3 and kb_set/3 do both in one call.

The control step finds the record once (engine_step/6) and hands it to what it runs
(working memory, the necessity units, the state code); a learner's hook finds it once per
call. A look-up costs a clause look-up and nb_getval/2; a part is one head unification
(record_get/3 has a clause for each part, as library(record)'s accessors do), so reading
a part the step already has the record for costs one inference.

The record is made at the first use of a knowledge base (a plain-swipl user may step
`user`); its global variable's name is made once and found afterwards by one clause look-up
(atom_concat/3 would look the atom up again at every call).
*/

:- dynamic key_/2.                  % KB, the name of its record's global variable
:- dynamic inner_/2.                % Key, Owner: Key's record is kept inside Owner's

%   The record, kb(Engine, Memory, Units, Learner, Tree, Task, Kept, Inner, Returns):
%     engine    engine(Run, Prev, Random) or none (engine.pl)
%     memory    wm(Clock, Span, Pairs, Elements, Now) (memory.pl)
%     units     Necessity-Y pairs (motivation.pl)
%     learner   the learner's own term, or none
%     tree      a tree (qtree.pl, tg_tree.pl), or none
%     task      the task a world learns next (world.pl), or none
%     kept      Slot-Snapshot pairs (engine_keep/2)
%     inner     inner(Key, Options, Record): the record of Key kept inside this one, with
%               the options of the learner that made it (kb_nest/3), or none
%     returns   ret(Lambda, Last): tg's return_lambda and its last update's state and
%               target (tg.pl, tg_update/2), or none

empty(kb(none, wm(0, default, [], [], []), [], none, none, none, [], none, none)).

new_record(KB, Record) :-
    must_be(atom, KB),
    atom_concat('$relrl_kb:', KB, Key),
    empty(Empty),
    nb_setval(Key, Empty),
    assertz(key_(KB, Key)),
    nb_getval(Key, Record).

%!  kb_record(+KB, -Record) is det.
%
%   Record is KB's record (the stored term itself), made empty at KB's first use; for a
%   key kb_nest/3 made, the record kept inside its owner's.
%
%   @error existence_error(kb_record, KB) if KB's owner no longer keeps its record.

kb_record(KB, Record) :-
    (   key_(KB, Key)
    ->  nb_getval(Key, Record)
    ;   inner_(KB, Owner)
    ->  kb_record(Owner, Outer),
        (   record_get(Outer, inner, inner(KB, _, Inner))
        ->  Record = Inner
        ;   existence_error(kb_record, KB)
        )
    ;   new_record(KB, Record)
    ).

%!  record_get(+Record, +Part, -Value) is semidet.
%
%   Value is the Part of Record (the stored term itself). A part never set has its empty
%   value: `none`, an empty memory, [] for the units and the kept snapshots. Fails when
%   Part is not a part (kb_get/3 tells the error).

record_get(kb(V, _, _, _, _, _, _, _, _), engine, V).
record_get(kb(_, V, _, _, _, _, _, _, _), memory, V).
record_get(kb(_, _, V, _, _, _, _, _, _), units, V).
record_get(kb(_, _, _, V, _, _, _, _, _), learner, V).
record_get(kb(_, _, _, _, V, _, _, _, _), tree, V).
record_get(kb(_, _, _, _, _, V, _, _, _), task, V).
record_get(kb(_, _, _, _, _, _, V, _, _), kept, V).
record_get(kb(_, _, _, _, _, _, _, V, _), inner, V).
record_get(kb(_, _, _, _, _, _, _, _, V), returns, V).

%!  record_set(+Record, +Part, +Value) is semidet.
%
%   Part of Record becomes a copy of Value. Fails when Part is not a part. The part's
%   position is read from record_get/3's clauses (a record of the positions), the one
%   table of the layout; a part is read by one head unification.

record_set(Record, Part, Value) :-
    record_get(kb(1, 2, 3, 4, 5, 6, 7, 8, 9), Part, I),
    nb_setarg(I, Record, Value).

%!  kb_get(+KB, +Part, -Value) is det.
%!  kb_set(+KB, +Part, +Value) is det.
%
%   record_get/3 and record_set/3 on KB's record.
%
%   @error domain_error(kb_part, Part) if Part is not a part.

kb_get(KB, Part, Value) :-
    kb_record(KB, Record),
    (   record_get(Record, Part, Value0)
    ->  Value = Value0
    ;   domain_error(kb_part, Part)
    ).

kb_set(KB, Part, Value) :-
    kb_record(KB, Record),
    (   record_set(Record, Part, Value)
    ->  true
    ;   domain_error(kb_part, Part)
    ).

%!  kb_nest(+Owner, +Key, +Options) is det.
%
%   Key's record becomes an empty record kept inside Owner's (its `inner` part, replacing
%   any), with Options: what a learner with a second tree keeps for it (ptg.pl keeps its
%   P-tree under a Key of its own, and its options). kb_get/3 and kb_set/3 on Key then
%   work on that record; forgetting Owner forgets it.

kb_nest(Owner, Key, Options) :-
    must_be(atom, Key),
    kb_record(Owner, Outer),
    empty(Empty),
    record_set(Outer, inner, inner(Key, Options, Empty)),
    kb_forget(Key),
    assertz(inner_(Key, Owner)).

%!  kb_forget(+KB) is det.
%
%   Delete KB's record (and the record kept inside it) and the name of its global
%   variable. For a record kept inside another, forget the name only: the record goes with
%   its owner's.

kb_forget(KB) :-
    must_be(atom, KB),
    (   retract(key_(KB, Key))
    ->  nb_delete(Key),
        retractall(inner_(_, KB))
    ;   retractall(inner_(KB, _))
    ).

%!  kb_record_exists(?KB) is nondet.
%
%   KB has a record of its own (it was used and not forgotten).

kb_record_exists(KB) :-
    key_(KB, _).
