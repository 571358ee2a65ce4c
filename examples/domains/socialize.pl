/*  The socialize necessity of the paper (da Silva & Romero 2012, section 5.2): the unit and
    its parameters, shared by the shipped domains. A domain includes it after
    prolog/relrl.pl is loaded, wherever the domain file lies:

        :- include(relrl_domains(socialize)).

    and declares its own satisfiers and unit inputs (which percepts lower or raise the need
    differ from world to world). The paper's input weights are positive magnitudes; declared
    as satisfiers they enter Eq. 1 negated, so contact lowers the need (docs/engine.md).
*/

necessity(socialize).
unit(socialize, bias, 1.00).
unit(socialize, recurrent_weight, 1.00).
unit(socialize, delta, 0.20).
unit(socialize, threshold, 0.50).
