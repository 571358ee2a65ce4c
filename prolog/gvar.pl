:- module(relrl_gvar,
          [ gvar_key/3            % +Prefix, +Name, -Key
          ]).
:- use_module(library(error)).

/** <module> Names of per-knowledge-base global variables

The engine keeps a knowledge base's state — its run and last step, the necessity units'
outputs, ETG's numbers, a tree — in global variables (nb_setval/2) named Prefix followed by
the knowledge base (or tree), so one knowledge base never sees another's. The control step
reads them every time unit: gvar_key/3 makes a name once (atom_concat/3 would look the atom
up again at every call) and finds it afterwards with one clause look-up.
*/

:- dynamic key_/3.                  % Prefix, Name, Key

%!  gvar_key(+Prefix:atom, +Name:atom, -Key:atom) is det.
%
%   Key is the atom Prefix followed by Name.

gvar_key(Prefix, Name, Key) :-
    (   key_(Prefix, Name, Key0)
    ->  Key = Key0
    ;   must_be(atom, Prefix),
        must_be(atom, Name),
        atom_concat(Prefix, Name, Key),
        assertz(key_(Prefix, Name, Key))
    ).
