/*  Stored state under signals: a signal handler that runs Prolog code in the middle of
    an update must not leave working memory or a tree's leaf with an open tail.

    The gateway runs every call in a foreign frame it discards afterwards, which undoes
    the trailed bindings of the call. A handler that stores a term on the global stack
    (nb_setval/2 of a float, as the gateway's old alarm did when it re-armed itself)
    freezes the stack; a list cell bound after that is trailed, and if the memory had been
    linked into its global variable rather than copied, undoing the binding cut the stored
    memory short with an unbound tail (the evaluation then failed on
    domain_error(working_memory_state, wm(..., [...|_]))). A tree's leaf linked into its
    tree (nb_linkarg/3) was open to the same: its entries are a list built by binding.
*/
:- use_module(library(plunit)).
:- use_module(library(lists)).
:- use_module('../../prolog/memory').
:- use_module('../../prolog/qtree').

:- begin_tests(stored_state_under_signals).

%   The handler another thread runs in this one: it writes a term to a global variable.
poke :-
    get_time(T),
    nb_setval(relrl_test_poke, T).

poker(Target, Queue) :-
    (   thread_get_message(Queue, stop, [timeout(0.00005)])
    ->  true
    ;   catch(thread_signal(Target, poke), error(existence_error(_, _), _), true),
        poker(Target, Queue)
    ).

percepts(I, Ps) :-
    X is I mod 3,
    nth0(X, [[see(face), pose(face, frontal), hear(attention), at(centre)],
             [see(face), pose(face, left), at(left)],
             [hear(attention), see(toy), at(toy, left), see(face)]], Ps).

%   Each insertion's bindings are undone after it (\+ \+, as the gateway's discarded
%   frame does); the memory read afterwards is a proper list every time.
memory_open_tails(KB, Steps, Open) :-
    wm_set_span(KB, 2),
    under_signals(
        aggregate_all(count,
                      ( between(1, Steps, I),
                        percepts(I, Ps),
                        \+ \+ wm_insert(KB, Ps),
                        wm_state(KB, wm(_, _, Pairs)),
                        \+ is_list(Pairs)
                      ), Open)).

%   A leaf's entries replaced every step, as ETG's update does.
leaf_open_tails(KB, Steps, Open) :-
    qtree_new(KB, [stimulus(a)]),
    qtree(KB, Tree),
    under_signals(
        aggregate_all(count,
                      ( between(1, Steps, I),
                        \+ \+ put_entry(Tree, I),
                        qtree_leaf(Tree, 0, _, Entries),
                        \+ is_list(Entries)
                      ), Open)).

put_entry(Tree, I) :-
    qtree_leaf(Tree, 0, _, Entries0),
    A is I mod 5,
    Q is (I * 7919) mod 101,
    qtree_put_entry(Entries0, e(A, Q, none), Entries),
    qtree_set_leaf(Tree, 0, 0, Entries).

:- meta_predicate under_signals(0).

under_signals(Goal) :-
    thread_self(Me),
    message_queue_create(Q),
    thread_create(poker(Me, Q), Poker, []),
    call_cleanup(
        Goal,
        ( thread_send_message(Q, stop),
          thread_join(Poker, _),
          message_queue_destroy(Q) )).

test(memory, [Open == 0]) :-
    memory_open_tails(relrl_test_signals, 50000, Open).

test(tree_leaf, [Open == 0]) :-
    leaf_open_tails(relrl_test_signals, 50000, Open).

:- end_tests(stored_state_under_signals).


