#include <iostream>
int main() { std::cout << "skyfarm-worker (skeleton)\n"; return 0; }
