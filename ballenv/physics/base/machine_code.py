"""Machine code only where Python calls, and one optimisation of each call tree: a compiled
function that only other compiled code calls keeps its LLVM IR, unoptimised as a module, and is
never turned into machine code on its own.

numba compiles every function into a code library and, as soon as it is compiled, optimises the
library's module (the function with every callee linked into it) and emits its machine code, so that
a pointer to it exists. A caller then links the callee's optimised IR into its own library and does
the same again: a callee at depth d of the call tree is optimised and emitted d + 1 times. The
simulator's kernels are a deep tree that only a few entry points (:func:`.jit.python_entry`) are
called through, so most of that work is thrown away (``benchmarks/results/compile_profile.md``).

:class:`LazyLibrary` (installed as the CPU codegen's library class by :func:`install`) postpones a
library's module optimisation and its machine code until a pointer to one of its functions is asked
for. A kernel compiled without Python wrappers (:func:`.jit.kernel`) is asked only for the wrapper
it does not have, so it stays IR, optimised function by function as numba does when it adds a module
(no inlining across functions yet); an entry point is asked for its wrapper, and its library, with
every callee linked in, is optimised by numba's module passes once, the whole call tree together
(LLVM's inliner works bottom-up through it), then emitted. Outside the few fast-math kernels LLVM
keeps IEEE arithmetic wherever it inlines, and the fingerprint (``benchmarks/fingerprint.py``) is
the one numba's own library gives. An inner kernel's cache entry holds its IR (numba's "bitcode"
kind) instead of machine code; a caller compiled in a later process links that IR. The environment
pointer numba stores in a library's module (exceptions, boxing) is stored when that module reaches
the engine (:func:`_set_env`).
"""

import llvmlite.binding as ll  # type: ignore[import-untyped]
from numba.core import codegen

# environment global name -> numba Environment, set once a module in the engine defines the global
_waiting_envs: dict[str, object] = {}


class LazyLibrary(codegen.JITCodeLibrary):
    """numba's JIT code library whose module optimisation and machine code wait for the first
    :meth:`get_pointer_to_function` of a function it defines (see the module doc)."""

    _deferred = False  # machine code not emitted yet
    _unoptimised = False  # module passes not run yet

    def _optimize_final_module(self):
        # a library being finalised: its module passes and machine code wait for a pointer
        self._deferred = self._unoptimised = True

    def _finalize_final_module(self):
        if not self._deferred:  # one loaded with its machine code from the cache
            self._emit()
            return
        self._verify_declare_only_symbols()
        self._finalized = True

    def _emit(self):
        """numba's final module steps: the module passes (if they wait), into the engine, machine
        code; then the waiting envs."""
        if self._unoptimised:
            self._unoptimised = False
            super()._optimize_final_module()
        super()._finalize_final_module()
        for name in list(_waiting_envs):
            if self._codegen._engine.get_global_value_address(name):
                _numba_set_env(self._codegen, name, _waiting_envs.pop(name))

    def _undefer(self):
        """Optimise the module and emit its machine code, as numba's ``finalize`` would have."""
        if self._deferred:
            self._deferred = False
            self._emit()

    def get_pointer_to_function(self, name):
        self._ensure_finalized()
        if self._deferred and not _defines(self._final_module, name):
            return 0  # a wrapper this kernel was compiled without: nothing to emit
        self._undefer()
        return super().get_pointer_to_function(name)

    def serialize_using_object_code(self):
        self._ensure_finalized()
        if self._deferred:
            return (self.name, "bitcode", self._final_module.as_bitcode())
        return super().serialize_using_object_code()

    @classmethod
    def _unserialize(cls, codegen_, state):
        name, kind, data = state
        if kind != "bitcode":
            return super()._unserialize(codegen_, state)
        self = codegen_.create_library(name)
        self._final_module = ll.parse_bitcode(data)
        self._deferred = self._unoptimised = True
        self._finalized = True
        return self


def _defines(module, name):
    """Whether LLVM ``module`` defines (not only declares) function ``name``."""
    try:
        return not module.get_function(name).is_declaration
    except NameError:
        return False


def _set_env(self, env_name, env):
    """numba's ``set_env``, or, while no module in the engine defines ``env_name`` (its library's
    machine code is deferred), kept until one does (:meth:`LazyLibrary._emit`)."""
    if self._engine.get_global_value_address(env_name):
        _numba_set_env(self, env_name, env)
    else:
        _waiting_envs[env_name] = env


_numba_set_env = codegen.JITCPUCodegen.set_env


def install():
    """Make :class:`LazyLibrary` the CPU JIT codegen's library class (idempotent)."""
    codegen.JITCPUCodegen._library_class = LazyLibrary
    codegen.JITCPUCodegen.set_env = _set_env
