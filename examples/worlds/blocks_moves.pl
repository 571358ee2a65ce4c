/*  Blocks world (examples/worlds/blocks.pl) with the reward of a cost per move: -1 for each
    move, 0 for the move that reaches the goal. Learned with gamma = 1, a Q-value is minus
    the number of moves still to make, and a wrong move costs exactly one more whatever the
    size of the world: the difference the learner must see does not shrink as the goal gets
    farther (with blocks.pl's reward, 1 at the goal discounted by gamma, it does).

        relrl learn examples/worlds/blocks_moves.pl --task stack
*/

:- include('blocks.pl').

discount(1).

reward(Goal, _, _, State, R) :-
    (   goal(Goal, State)
    ->  R = 0
    ;   R = -1
    ).
