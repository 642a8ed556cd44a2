"""Cache hints for the compiled event loop.

At large N the event loop waits on memory: the next event's disk lies anywhere in the
arrays. :func:`prefetch` asks the CPU to start loading an element early (LLVM's
``llvm.prefetch``, read, high locality), while the current event is still being worked on.
A hint changes no result; an address outside the array is harmless to the CPU but the index
must still lie inside it, as for any element access.
"""

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def prefetch(typingctx, array, index):
    """Start loading ``array[index]`` (the start of row ``index`` of a 2-d array) into cache."""
    if not isinstance(array, types.Array) or not isinstance(index, types.Integer):
        return None

    def codegen(context, builder, signature, args):
        array_type, index_type = signature.args
        data = context.make_array(array_type)(context, builder, args[0])
        row = context.cast(builder, args[1], index_type, types.intp)
        indices = [row] + [context.get_constant(types.intp, 0)] * (array_type.ndim - 1)
        pointer = cgutils.get_item_pointer2(
            context, builder, data.data, cgutils.unpack_tuple(builder, data.shape),
            cgutils.unpack_tuple(builder, data.strides), array_type.layout, indices,
            wraparound=False)
        byte_pointer = builder.bitcast(pointer, ir.IntType(8).as_pointer())
        i32 = ir.IntType(32)
        function = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [byte_pointer.type, i32, i32, i32]),
            "llvm.prefetch.p0")
        builder.call(function, [byte_pointer, i32(0), i32(3), i32(1)])
        return context.get_dummy_value()

    return types.void(array, index), codegen
