"""Write the generated header of PAMINSA's general model, unbalanced, as bench/paminsa_general.hpp
builds it in C++ (the paper's parameters, no counterweights): mechbal_bench_paminsa.hpp in the
folder given. bench_generated.cpp checks at setup that it moves as the closed form."""
import sys

from mechbal.codegen import generate
from mechbal.config import read_case
from mechbal.papers.paminsa import paminsa_mechanism
from mechbal.papers.paminsa.runner import parameters_from_config

mechanism = paminsa_mechanism(parameters_from_config(read_case("paminsa")), balanced=False)
generate(mechanism, name="mechbal_bench_paminsa", frames=[]).write(sys.argv[1])
