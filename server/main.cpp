#include <iostream>
int main() { std::cout << "skyfarm-server (skeleton)\n"; return 0; }
