// ThreadSanitizer: the Debian DDS libraries are not instrumented, so TSan sees their internal
// synchronisation (their own atomics and lock-free queues) only partly and reports races inside
// them (recvmsg into a buffer another Cyclone thread copies, mutexes in memory it recycled).
// Reports with a frame in those libraries are suppressed; a race between two stacks of our own
// code (bridge thread vs. test thread) is still reported. Include in exactly one translation
// unit per test program.
#pragma once

extern "C" const char* __tsan_default_suppressions() {
  return "called_from_lib:libddsc.so.0debian\n"
         "race:libddsc.so.0debian\n"
         "called_from_lib:libfastrtps.so.2.9\n"
         "race:libfastrtps.so.2.9\n";
}
