// Deliberate violations for the integer-only checker's own test: each function must be caught.
#include <cmath>
#include <cstdlib>
#include <stdexcept>

extern "C" {

int smxCanaryFp(int a, int b) {
  return static_cast<int>(static_cast<float>(a) * 0.5f + b);
}

long double smxCanarySoftFloat(long double a, long double b) {
  return a * b;
}

double smxCanaryLibm(double x) {
  return std::atan2(x, 1.0 + x);
}

int* smxCanaryHeap(int n) {
  return new int[static_cast<unsigned>(n)];
}

void* smxCanaryMalloc(unsigned n) {
  return std::malloc(n);
}

int smxCanaryThrow(int x) {
  if (x < 0) {
    throw std::out_of_range("negative");
  }
  return x;
}
}
