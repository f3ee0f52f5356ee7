#include <iostream>

#include "cli.h"

int main(int argc, char** argv) { return hybridcont::app::RunCli(argc, argv, std::cout, std::cerr); }
