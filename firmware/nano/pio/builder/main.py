# SCons build script of the offline Nigel AVR platform (PlatformIO runs it for every env whose
# platform is this folder). It compiles with Debian's avr-gcc 5.4 and avr-libc, builds Debian's
# Arduino AVR core (arduino-core-avr) as the framework library, and uploads with avrdude.
# The compile and link flags are the CMake AVR build's (firmware/nano/avr/CMakeLists.txt), so
# both builds give an ELF with the same section sizes (test firmware.pio_build_matches_cmake).
import os

from SCons.Script import AlwaysBuild, Default, DefaultEnvironment  # type: ignore

env = DefaultEnvironment()
board = env.BoardConfig()

arduino_avr_dir = os.environ.get("NIGEL_ARDUINO_AVR_DIR", "/usr/share/arduino/hardware/arduino/avr")
core_dir = os.path.join(arduino_avr_dir, "cores", board.get("build.core"))
variant_dir = os.path.join(arduino_avr_dir, "variants", board.get("build.variant"))
if not os.path.isfile(os.path.join(core_dir, "Arduino.h")):
    env.Exit(
        "Error: the Arduino AVR core is not in %s (Debian package arduino-core-avr; or set "
        "NIGEL_ARDUINO_AVR_DIR)" % core_dir
    )

mcu = board.get("build.mcu")
f_cpu = board.get("build.f_cpu").rstrip("L")
env.Replace(
    AR="avr-gcc-ar",  # the LTO-aware archiver: -flto objects in archives keep their IR
    AS="avr-gcc",
    CC="avr-gcc",
    CXX="avr-g++",
    GDB="avr-gdb",
    OBJCOPY="avr-objcopy",
    RANLIB="avr-gcc-ranlib",
    SIZETOOL="avr-size",
    ARFLAGS=["rc"],
    PROGNAME="firmware",
    PROGSUFFIX=".elf",
    SIZEPROGREGEXP=r"^(?:\.text|\.data|\.bootloader)\s+(\d+).*",
    SIZEDATAREGEXP=r"^(?:\.data|\.bss|\.noinit)\s+(\d+).*",
    SIZEEEPROMREGEXP=r"^(?:\.eeprom)\s+(\d+).*",
    SIZECHECKCMD="$SIZETOOL -A -d $SOURCES",
    SIZEPRINTCMD="$SIZETOOL --mcu=%s -C -d $SOURCES" % mcu,
)

# The CMake AVR build's flags, one for one (firmware/nano/avr/CMakeLists.txt).
common = ["-mmcu=%s" % mcu, "-Os", "-g", "-ffunction-sections", "-fdata-sections", "-flto"]
env.Append(
    ASFLAGS=common + ["-x", "assembler-with-cpp"],
    CCFLAGS=common,
    CFLAGS=["-std=gnu11"],
    CXXFLAGS=["-std=gnu++14", "-fno-exceptions", "-fno-rtti", "-fno-threadsafe-statics"],
    CPPDEFINES=[
        ("F_CPU", f_cpu + "UL"),
        ("ARDUINO", 10807),
        "ARDUINO_ARCH_AVR",
        ("DECIMAL_DIG", "__DECIMAL_DIG__"),
    ],
    CPPPATH=[core_dir, variant_dir],
    LINKFLAGS=["-mmcu=%s" % mcu, "-Os", "-flto", "-fuse-linker-plugin", "-Wl,--gc-sections"],
)
env.Append(ASPPFLAGS=env.get("ASFLAGS", [])[:])

# Debian's Arduino core as the framework library (only what is referenced gets linked). Its
# wiring_pulse.S and wiring_pulse.c would both become wiring_pulse.o in one folder, so the
# assembly files build into a library of their own.
core_asm = sorted(f for f in os.listdir(core_dir) if f.endswith(".S"))
env.Prepend(
    LIBS=[
        env.BuildLibrary(
            os.path.join("$BUILD_DIR", "FrameworkArduino"),
            core_dir,
            src_filter=["+<*>"] + ["-<%s>" % f for f in core_asm],
        ),
        env.BuildLibrary(
            os.path.join("$BUILD_DIR", "FrameworkArduinoAsm"),
            core_dir,
            src_filter=["-<*>"] + ["+<%s>" % f for f in core_asm],
        ),
    ]
)

target_elf = env.BuildProgram()
target_hex = env.Command(
    os.path.join("$BUILD_DIR", "${PROGNAME}.hex"),
    target_elf,
    env.VerboseAction("$OBJCOPY -O ihex -R .eeprom $SOURCES $TARGET", "Building $TARGET"),
)
AlwaysBuild(env.Alias("nobuild", target_hex))
Default([env.Alias("buildprog", target_hex)])

AlwaysBuild(
    env.Alias(
        "size",
        target_elf,
        env.VerboseAction("$SIZEPRINTCMD", "Calculating size $SOURCE"),
    )
)

# Upload over the Nano's serial bootloader (STK500v1, "arduino" in avrdude): the speed is the
# bootloader's (57600 for the old ATmegaBOOT, 115200 for Optiboot: board_upload.speed).
upload_speed = env.subst("$UPLOAD_SPEED") or str(board.get("upload.speed"))
upload_protocol = env.subst("$UPLOAD_PROTOCOL") or board.get("upload.protocol")
env.Replace(
    UPLOADER="avrdude",
    UPLOADERFLAGS=[
        "-p",
        mcu,
        "-c",
        upload_protocol,
        "-P",
        '"$UPLOAD_PORT"',
        "-b",
        upload_speed,
        "-D",
    ],
    UPLOADCMD="$UPLOADER $UPLOADERFLAGS -U flash:w:$SOURCES:i",
)
if "UPLOAD_FLAGS" in env:
    env.Append(UPLOADERFLAGS=["$UPLOAD_FLAGS"])
AlwaysBuild(
    env.Alias(
        "upload",
        target_hex,
        [
            env.VerboseAction(env.AutodetectUploadPort, "Looking for upload port..."),
            env.VerboseAction("$UPLOADCMD", "Uploading $SOURCE"),
        ],
    )
)
AlwaysBuild(
    env.Alias(
        "checkprogsize",
        target_elf,
        env.VerboseAction(env.CheckUploadSize, "Checking size $PIOMAINPROG"),
    )
)
