; ModuleID = 'kernel'
source_filename = "kernel"
target datalayout = "e-m:e-p270:32:32-p271:32:32-p272:64:64-i64:64-f80:128-n8:16:32:64-S128"
target triple = "x86_64-pc-linux-gnu"

%struct.RuntimeContext.22 = type { i8*, %struct.LLVMRuntime.21*, i32, i64* }
%struct.LLVMRuntime.21 = type { %struct.PreallocatedMemoryChunk.16, %struct.PreallocatedMemoryChunk.16, i8* (i8*, i64, i64)*, void (i8*)*, void (i8*, ...)*, i32 (i8*, i64, i8*, %struct.__va_list_tag.17*)*, i8*, [512 x i8*], [512 x i64], i8*, void (i8*, i32, i32, i8*, void (i8*, i32, i32)*)*, [1024 x %struct.ListManager.18*], [1024 x %struct.NodeManager.19*], [1024 x i8*], i8*, %struct.RandState.20*, i8*, void (i8*, i8*)*, void (i8*)*, [2048 x i8], [32 x i64], i32, i64, i8*, i32, i32, i64 }
%struct.PreallocatedMemoryChunk.16 = type { i8*, i8*, i64 }
%struct.__va_list_tag.17 = type { i32, i32, i8*, i8* }
%struct.ListManager.18 = type { [131072 x i8*], i64, i64, i32, i32, i32, %struct.LLVMRuntime.21* }
%struct.NodeManager.19 = type <{ %struct.LLVMRuntime.21*, i32, i32, i32, i32, %struct.ListManager.18*, %struct.ListManager.18*, %struct.ListManager.18*, i32, [4 x i8] }>
%struct.RandState.20 = type { i32, i32, i32, i32, i32 }

; Function Attrs: mustprogress nofree norecurse nosync nounwind willreturn
define void @snode_writer_8_kernel_0_serial(%struct.RuntimeContext.22* %context) local_unnamed_addr #0 {
entry:
  %0 = bitcast %struct.RuntimeContext.22* %context to { i32 }**
  %1 = load { i32 }*, { i32 }** %0, align 8
  %2 = getelementptr { i32 }, { i32 }* %1, i64 0, i32 0
  %3 = load i32, i32* %2, align 4
  %4 = getelementptr inbounds %struct.RuntimeContext.22, %struct.RuntimeContext.22* %context, i64 0, i32 1
  %5 = load %struct.LLVMRuntime.21*, %struct.LLVMRuntime.21** %4, align 8
  %6 = getelementptr inbounds %struct.LLVMRuntime.21, %struct.LLVMRuntime.21* %5, i64 0, i32 7, i64 0
  %7 = load i8*, i8** %6, align 8
  %getch.i = getelementptr i8, i8* %7, i64 32
  %8 = bitcast i8* %getch.i to i32*
  store i32 %3, i32* %8, align 4
  ret void
}

attributes #0 = { mustprogress nofree norecurse nosync nounwind willreturn }

!llvm.ident = !{!0}
!llvm.module.flags = !{!1, !2, !3, !4, !5}

!0 = !{!"Ubuntu clang version 14.0.6"}
!1 = !{i32 1, !"wchar_size", i32 4}
!2 = !{i32 7, !"PIC Level", i32 2}
!3 = !{i32 7, !"PIE Level", i32 2}
!4 = !{i32 7, !"uwtable", i32 1}
!5 = !{i32 7, !"frame-pointer", i32 2}
