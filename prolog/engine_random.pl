:- module(relrl_engine_random,
          [ random_owner/1,       % ?Owner
            random_park/0,
            random_claim/2,       % +KB, +Engine
            random_now/3,         % +KB, +Engine, -Random
            random_replace/3,     % +KB, +Engine, +Random
            random_fresh/2,       % +Seed, -Random
            random_disown/1       % +KB
          ]).
:- use_module(library(error)).
:- use_module(kbstate).
:- use_module(guard, [call_context/2, set_call_context/2]).

/** <module> Each knowledge base's random stream

Each knowledge base owns its random stream, so two agents in one process give the same
trajectories as each alone. Learners just use library(random): SWI-Prolog has one random
generator (per thread), and the engine keeps in it the stream of the knowledge base that
stepped last, swapping only when another knowledge base steps (a robot stepping one agent
never saves or restores the generator's 2.5 KB state). The engine's own predicates that
touch the generator first put that stream away with its knowledge base (random_park/0).

A knowledge base's stream is the third argument of its engine term, engine(Run, Prev,
Random) (the `engine` part of its record, engine.pl), while the generator does not hold
it; which knowledge base's stream the generator holds is the guard's call context
`random_owner`. Only this module reads or writes either.
*/

%!  random_owner(?Owner) is det.
%
%   The generator holds Owner's stream (the knowledge base that stepped last), or that of
%   none (`none`): one per thread, as the generator is.

random_owner(Owner) :-
    call_context(random_owner, Owner).

%!  random_park is det.
%
%   Put the stream the generator holds away with its knowledge base.

random_park :-
    (   random_owner(Owner),
        Owner \== none
    ->  (   kb_record_exists(Owner),
            kb_get(Owner, engine, Engine),
            Engine \== none
        ->  random_property(state(Random)),
            nb_setarg(3, Engine, Random)
        ;   true
        ),
        set_call_context(random_owner, none)
    ;   true
    ).

%!  random_claim(+KB, +Engine) is det.
%
%   Load KB's stream into the generator (Engine is KB's engine term), where it stays
%   until another knowledge base claims it or random_park/0 puts it away.

random_claim(KB, Engine) :-
    (   random_owner(KB)
    ->  true
    ;   random_park,
        arg(3, Engine, Random),
        set_random(state(Random)),
        set_call_context(random_owner, KB)
    ).

%!  random_now(+KB, +Engine, -Random) is det.
%
%   Random is KB's stream as it is now: the generator's state while it holds it.

random_now(KB, Engine, Random) :-
    (   random_owner(KB)
    ->  random_property(state(Random))
    ;   arg(3, Engine, Random)
    ).

%!  random_replace(+KB, +Engine, +Random) is det.
%
%   KB's stream is now Random (the generator loads it when KB next needs it).

random_replace(KB, Engine, Random) :-
    (   random_owner(KB)                % first: an interrupt between the two writes
    ->  set_call_context(random_owner, none)     % must not let a later park overwrite
    ;   true                                    % Random with the generator's state
    ),
    nb_setarg(3, Engine, Random).

%!  random_fresh(+Seed, -Random) is det.
%
%   Random is a new stream seeded with Seed (an integer; `none`: from the clock). The
%   stream the generator held is put away first.
%
%   @error type_error(integer, Seed) if Seed is neither.

random_fresh(Seed, Random) :-
    random_park,
    (   integer(Seed)
    ->  set_random(seed(Seed))
    ;   Seed == none
    ->  set_random(seed(random))
    ;   type_error(integer, Seed)
    ),
    random_property(state(Random)).

%!  random_disown(+KB) is det.
%
%   KB goes: the generator no longer counts as holding its stream.

random_disown(KB) :-
    (   random_owner(KB)
    ->  set_call_context(random_owner, none)
    ;   true
    ).
