# CMake toolchain: Debian 12 x86_64 host -> bare-metal Cortex-M4F (STM32F405, issue 36).
# Debian's gcc-arm-none-eabi 12.2 with picolibc (picolibc-arm-none-eabi and its libstdc++,
# libstdc++-arm-none-eabi-picolibc); the start-up, vector table and linker script are the
# project's own (board/), not picolibc's crt0 or picolibc.ld.
#   apt-get install gcc-arm-none-eabi picolibc-arm-none-eabi libstdc++-arm-none-eabi-picolibc
# Usage: cmake --preset mcu-stm32f405 (sets ODO_TARGET_MCU=ON: only the portable rooms and board/).

set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
set(CMAKE_OBJCOPY arm-none-eabi-objcopy CACHE FILEPATH "objcopy")
set(CMAKE_SIZE arm-none-eabi-size CACHE FILEPATH "size")
# Test programs of try_compile cannot link without the board's start-up.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# -ffp-contract=off: no fused multiply-add, so that double arithmetic rounds exactly as on the
# host (x86-64 builds never contract either): the pose is bit-exact with odometryd's.
set(ODO_MCU_FLAGS "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -ffp-contract=off \
-ffunction-sections -fdata-sections --specs=picolibcpp.specs")
set(CMAKE_C_FLAGS_INIT "${ODO_MCU_FLAGS}")
set(CMAKE_CXX_FLAGS_INIT "${ODO_MCU_FLAGS} -fno-exceptions -fno-rtti -fno-threadsafe-statics \
-fno-use-cxa-atexit")
set(CMAKE_ASM_FLAGS_INIT "${ODO_MCU_FLAGS}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-Wl,--gc-sections")

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
