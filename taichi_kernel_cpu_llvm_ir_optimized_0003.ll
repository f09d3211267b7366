; ModuleID = 'kernel'
source_filename = "kernel"
target datalayout = "e-m:e-p270:32:32-p271:32:32-p272:64:64-i64:64-f80:128-n8:16:32:64-S128"
target triple = "x86_64-pc-linux-gnu"

%struct.RuntimeContext.35 = type { i8*, %struct.LLVMRuntime.34*, i32, i64* }
%struct.LLVMRuntime.34 = type { %struct.PreallocatedMemoryChunk.29, %struct.PreallocatedMemoryChunk.29, i8* (i8*, i64, i64)*, void (i8*)*, void (i8*, ...)*, i32 (i8*, i64, i8*, %struct.__va_list_tag.30*)*, i8*, [512 x i8*], [512 x i64], i8*, void (i8*, i32, i32, i8*, void (i8*, i32, i32)*)*, [1024 x %struct.ListManager.31*], [1024 x %struct.NodeManager.32*], [1024 x i8*], i8*, %struct.RandState.33*, i8*, void (i8*, i8*)*, void (i8*)*, [2048 x i8], [32 x i64], i32, i64, i8*, i32, i32, i64 }
%struct.PreallocatedMemoryChunk.29 = type { i8*, i8*, i64 }
%struct.__va_list_tag.30 = type { i32, i32, i8*, i8* }
%struct.ListManager.31 = type { [131072 x i8*], i64, i64, i32, i32, i32, %struct.LLVMRuntime.34* }
%struct.NodeManager.32 = type <{ %struct.LLVMRuntime.34*, i32, i32, i32, i32, %struct.ListManager.31*, %struct.ListManager.31*, %struct.ListManager.31*, i32, [4 x i8] }>
%struct.RandState.33 = type { i32, i32, i32, i32, i32 }

; Function Attrs: nofree nosync nounwind
define void @_convert_c92_0_kernel_0_serial(%struct.RuntimeContext.35* nocapture readonly %context) local_unnamed_addr #0 {
entry:
  %0 = alloca [96 x i32], align 4
  %1 = alloca [32 x i32], align 4
  %2 = bitcast [32 x i32]* %1 to <16 x i32>*
  %3 = alloca <16 x i32>, align 4
  %4 = bitcast <16 x i32>* %3 to i8*
  %5 = alloca <16 x i32>, align 4
  %6 = bitcast <16 x i32>* %5 to i8*
  %7 = bitcast %struct.RuntimeContext.35* %context to { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }**
  %8 = load { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }*, { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }** %7, align 8
  %9 = getelementptr { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }, { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }* %8, i64 0, i32 4
  %10 = load i32, i32* %9, align 4
  %11 = sdiv i32 %10, 4
  %12 = icmp slt i32 %10, 0
  %13 = shl nsw i32 %11, 2
  %14 = icmp ne i32 %13, %10
  %15 = and i1 %12, %14
  %.neg = sext i1 %15 to i32
  %16 = add nsw i32 %11, %.neg
  %17 = getelementptr { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }, { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }* %8, i64 0, i32 2, i32 0, i32 0
  %18 = load i32, i32* %17, align 4
  %19 = sdiv i32 %18, %16
  %20 = mul i32 %16, %19
  %21 = xor i32 %16, %18
  %22 = icmp slt i32 %21, 0
  %23 = icmp ne i32 %18, 0
  %24 = icmp ne i32 %20, %18
  %25 = and i1 %23, %22
  %26 = and i1 %24, %25
  %.neg23 = sext i1 %26 to i32
  %27 = add i32 %19, %.neg23
  %28 = add nsw i32 %16, 15
  %29 = sdiv i32 %28, 16
  %30 = icmp slt i32 %16, -15
  %31 = shl nsw i32 %29, 4
  %32 = icmp ne i32 %31, %28
  %33 = and i1 %30, %32
  %.neg24 = sext i1 %33 to i32
  %34 = add nsw i32 %29, %.neg24
  %35 = mul i32 %34, %27
  %36 = icmp sgt i32 %35, 0
  br i1 %36, label %for_loop_body.lr.ph, label %after_for

for_loop_body.lr.ph:                              ; preds = %entry
  %37 = mul i32 %16, 3
  %38 = getelementptr inbounds <16 x i32>, <16 x i32>* %3, i64 0, i64 8
  %39 = getelementptr inbounds <16 x i32>, <16 x i32>* %5, i64 0, i64 8
  %40 = icmp slt i32 %34, 0
  %41 = bitcast [96 x i32]* %0 to i8*
  %42 = bitcast [32 x i32]* %1 to i8*
  %broadcast.splatinsert71 = insertelement <8 x i32> poison, i32 %37, i64 0
  %broadcast.splat72 = shufflevector <8 x i32> %broadcast.splatinsert71, <8 x i32> poison, <8 x i32> zeroinitializer
  %43 = bitcast [96 x i32]* %0 to <16 x i32>*
  %44 = getelementptr inbounds [96 x i32], [96 x i32]* %0, i64 0, i64 16
  %45 = bitcast i32* %44 to <16 x i32>*
  %46 = getelementptr inbounds [96 x i32], [96 x i32]* %0, i64 0, i64 32
  %47 = bitcast i32* %46 to <16 x i32>*
  %48 = getelementptr inbounds [96 x i32], [96 x i32]* %0, i64 0, i64 48
  %49 = bitcast i32* %48 to <16 x i32>*
  %50 = getelementptr [32 x i32], [32 x i32]* %1, i64 0, i64 16
  %51 = bitcast i32* %50 to <16 x i32>*
  %52 = getelementptr inbounds [96 x i32], [96 x i32]* %0, i64 0, i64 64
  %53 = bitcast i32* %52 to <16 x i32>*
  %54 = getelementptr [96 x i32], [96 x i32]* %0, i64 0, i64 80
  %55 = bitcast i32* %54 to <16 x i32>*
  %56 = bitcast <16 x i32>* %3 to <8 x i32>*
  %57 = bitcast <16 x i32>* %5 to <8 x i32>*
  %58 = bitcast i32* %38 to <8 x i32>*
  %59 = bitcast i32* %39 to <8 x i32>*
  %60 = shl i32 %34, 4
  %61 = mul i32 %16, 6
  %62 = mul i32 %34, 48
  %63 = sub i32 %61, %62
  %64 = mul nsw i32 %11, 3
  %65 = mul nsw i32 %.neg, 3
  %66 = add i32 %64, %65
  %67 = shl nsw i32 %16, 1
  %68 = sub i32 %67, %60
  %69 = sub i32 %16, %60
  br label %for_loop_body

for_loop_body:                                    ; preds = %for_loop_body.lr.ph, %after_for15
  %lsr.iv127 = phi i32 [ 0, %for_loop_body.lr.ph ], [ %lsr.iv.next128, %after_for15 ]
  %lsr.iv104 = phi i32 [ 0, %for_loop_body.lr.ph ], [ %lsr.iv.next105, %after_for15 ]
  %lsr.iv = phi i32 [ %16, %for_loop_body.lr.ph ], [ %lsr.iv.next, %after_for15 ]
  %.02132 = phi i32 [ 0, %for_loop_body.lr.ph ], [ %366, %after_for15 ]
  %70 = sdiv i32 %.02132, %34
  %71 = mul i32 %70, %34
  %72 = icmp ne i32 %.02132, 0
  %73 = icmp ne i32 %71, %.02132
  %74 = and i1 %72, %40
  %75 = and i1 %74, %73
  %.neg25 = sext i1 %75 to i32
  %76 = add i32 %70, %.neg25
  %77 = mul i32 %76, %34
  %78 = sub i32 %.02132, %77
  %79 = shl i32 %78, 4
  %80 = sub i32 %16, %79
  %81 = tail call i32 @llvm.smin.i32(i32 %80, i32 16)
  %82 = mul i32 %76, %16
  %83 = mul i32 %82, 6
  %84 = mul i32 %78, 48
  %85 = add i32 %84, %83
  call void @llvm.memset.p0i8.i64(i8* noundef nonnull align 4 dereferenceable(384) %41, i8 0, i64 384, i1 false)
  %86 = load { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }*, { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }** %7, align 8
  %87 = icmp sgt i32 %80, 0
  br i1 %87, label %for_loop_body1.lr.ph, label %after_for3

for_loop_body1.lr.ph:                             ; preds = %for_loop_body
  %88 = getelementptr { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }, { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }* %86, i64 0, i32 0, i32 1
  %89 = sext i32 %81 to i64
  %smax = call i64 @llvm.smax.i64(i64 %89, i64 1)
  %min.iters.check = icmp ult i64 %smax, 8
  br i1 %min.iters.check, label %for_loop_body1.preheader, label %vector.ph58

vector.ph58:                                      ; preds = %for_loop_body1.lr.ph
  %broadcast.splatinsert = insertelement <8 x i32> poison, i32 %85, i64 0
  %broadcast.splat = shufflevector <8 x i32> %broadcast.splatinsert, <8 x i32> poison, <8 x i32> zeroinitializer
  %90 = load i32*, i32** %88, align 8
  %broadcast.splatinsert63 = insertelement <8 x i32*> poison, i32* %90, i64 0
  %broadcast.splat64 = shufflevector <8 x i32*> %broadcast.splatinsert63, <8 x i32*> poison, <8 x i32> zeroinitializer
  %91 = mul i32 %60, %76
  %92 = add i32 %lsr.iv, %91
  %smin = call i32 @llvm.smin.i32(i32 %92, i32 16)
  %93 = sext i32 %smin to i64
  %smax103 = call i64 @llvm.smax.i64(i64 %93, i64 1)
  %94 = lshr i64 %smax103, 3
  %95 = shl nuw nsw i64 %94, 3
  br label %vector.body61

vector.body61:                                    ; preds = %vector.body61, %vector.ph58
  %index62 = phi i64 [ 0, %vector.ph58 ], [ %index.next82, %vector.body61 ]
  %vec.phi = phi <8 x i32> [ zeroinitializer, %vector.ph58 ], [ %120, %vector.body61 ]
  %vec.ind = phi <8 x i32> [ <i32 0, i32 1, i32 2, i32 3, i32 4, i32 5, i32 6, i32 7>, %vector.ph58 ], [ %vec.ind.next, %vector.body61 ]
  %96 = mul <8 x i32> %vec.ind, <i32 3, i32 3, i32 3, i32 3, i32 3, i32 3, i32 3, i32 3>
  %97 = add <8 x i32> %96, %broadcast.splat
  %98 = sext <8 x i32> %97 to <8 x i64>
  %99 = getelementptr i32, <8 x i32*> %broadcast.splat64, <8 x i64> %98
  %wide.masked.gather = call <8 x i32> @llvm.masked.gather.v8i32.v8p0i32(<8 x i32*> %99, i32 4, <8 x i1> <i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true>, <8 x i32> undef)
  %scevgep86 = getelementptr i32, i32* %54, i64 %index62
  %scevgep8687 = bitcast i32* %scevgep86 to <8 x i32>*
  %scevgep88 = getelementptr <8 x i32>, <8 x i32>* %scevgep8687, i64 -10
  store <8 x i32> %wide.masked.gather, <8 x i32>* %scevgep88, align 4
  %100 = or <8 x i32> %wide.masked.gather, %vec.phi
  %101 = add <8 x i32> %97, <i32 1, i32 1, i32 1, i32 1, i32 1, i32 1, i32 1, i32 1>
  %102 = sext <8 x i32> %101 to <8 x i64>
  %103 = getelementptr i32, <8 x i32*> %broadcast.splat64, <8 x i64> %102
  %wide.masked.gather67 = call <8 x i32> @llvm.masked.gather.v8i32.v8p0i32(<8 x i32*> %103, i32 4, <8 x i1> <i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true>, <8 x i32> undef)
  %scevgep91 = getelementptr <8 x i32>, <8 x i32>* %scevgep8687, i64 -8
  store <8 x i32> %wide.masked.gather67, <8 x i32>* %scevgep91, align 4
  %104 = or <8 x i32> %100, %wide.masked.gather67
  %105 = add <8 x i32> %97, <i32 2, i32 2, i32 2, i32 2, i32 2, i32 2, i32 2, i32 2>
  %106 = sext <8 x i32> %105 to <8 x i64>
  %107 = getelementptr i32, <8 x i32*> %broadcast.splat64, <8 x i64> %106
  %wide.masked.gather70 = call <8 x i32> @llvm.masked.gather.v8i32.v8p0i32(<8 x i32*> %107, i32 4, <8 x i1> <i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true>, <8 x i32> undef)
  %scevgep94 = getelementptr <8 x i32>, <8 x i32>* %scevgep8687, i64 -6
  store <8 x i32> %wide.masked.gather70, <8 x i32>* %scevgep94, align 4
  %108 = or <8 x i32> %104, %wide.masked.gather70
  %109 = add <8 x i32> %97, %broadcast.splat72
  %110 = sext <8 x i32> %109 to <8 x i64>
  %111 = getelementptr i32, <8 x i32*> %broadcast.splat64, <8 x i64> %110
  %wide.masked.gather75 = call <8 x i32> @llvm.masked.gather.v8i32.v8p0i32(<8 x i32*> %111, i32 4, <8 x i1> <i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true>, <8 x i32> undef)
  %scevgep97 = getelementptr <8 x i32>, <8 x i32>* %scevgep8687, i64 -4
  store <8 x i32> %wide.masked.gather75, <8 x i32>* %scevgep97, align 4
  %112 = or <8 x i32> %108, %wide.masked.gather75
  %113 = add <8 x i32> %109, <i32 1, i32 1, i32 1, i32 1, i32 1, i32 1, i32 1, i32 1>
  %114 = sext <8 x i32> %113 to <8 x i64>
  %115 = getelementptr i32, <8 x i32*> %broadcast.splat64, <8 x i64> %114
  %wide.masked.gather78 = call <8 x i32> @llvm.masked.gather.v8i32.v8p0i32(<8 x i32*> %115, i32 4, <8 x i1> <i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true>, <8 x i32> undef)
  %scevgep100 = getelementptr <8 x i32>, <8 x i32>* %scevgep8687, i64 -2
  store <8 x i32> %wide.masked.gather78, <8 x i32>* %scevgep100, align 4
  %116 = or <8 x i32> %112, %wide.masked.gather78
  %117 = add <8 x i32> %109, <i32 2, i32 2, i32 2, i32 2, i32 2, i32 2, i32 2, i32 2>
  %118 = sext <8 x i32> %117 to <8 x i64>
  %119 = getelementptr i32, <8 x i32*> %broadcast.splat64, <8 x i64> %118
  %wide.masked.gather81 = call <8 x i32> @llvm.masked.gather.v8i32.v8p0i32(<8 x i32*> %119, i32 4, <8 x i1> <i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true, i1 true>, <8 x i32> undef)
  store <8 x i32> %wide.masked.gather81, <8 x i32>* %scevgep8687, align 4
  %120 = or <8 x i32> %116, %wide.masked.gather81
  %index.next82 = add nuw i64 %index62, 8
  %vec.ind.next = add <8 x i32> %vec.ind, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %121 = icmp eq i64 %95, %index.next82
  br i1 %121, label %middle.block56, label %vector.body61, !llvm.loop !6

middle.block56:                                   ; preds = %vector.body61
  %n.vec = and i64 %smax, 9223372036854775800
  %122 = call i32 @llvm.vector.reduce.or.v8i32(<8 x i32> %120)
  %cmp.n60 = icmp eq i64 %smax, %n.vec
  br i1 %cmp.n60, label %after_for3, label %for_loop_body1.preheader

for_loop_body1.preheader:                         ; preds = %for_loop_body1.lr.ph, %middle.block56
  %indvars.iv.ph = phi i64 [ 0, %for_loop_body1.lr.ph ], [ %n.vec, %middle.block56 ]
  %.02027.ph = phi i32 [ 0, %for_loop_body1.lr.ph ], [ %122, %middle.block56 ]
  %123 = load i32*, i32** %88, align 8
  %124 = mul i32 %63, %76
  %125 = add i32 %lsr.iv104, %124
  %126 = trunc i64 %indvars.iv.ph to i32
  %127 = mul nuw nsw i32 %126, 3
  %128 = add i32 %125, %127
  br label %for_loop_body1

after_for.loopexit:                               ; preds = %after_for15
  br label %after_for

after_for:                                        ; preds = %after_for.loopexit, %entry
  ret void

for_loop_body1:                                   ; preds = %for_loop_body1.preheader, %for_loop_body1
  %lsr.iv106 = phi i32 [ %128, %for_loop_body1.preheader ], [ %lsr.iv.next107, %for_loop_body1 ]
  %indvars.iv = phi i64 [ %indvars.iv.next, %for_loop_body1 ], [ %indvars.iv.ph, %for_loop_body1.preheader ]
  %.02027 = phi i32 [ %158, %for_loop_body1 ], [ %.02027.ph, %for_loop_body1.preheader ]
  %129 = sext i32 %lsr.iv106 to i64
  %130 = getelementptr i32, i32* %123, i64 %129
  %131 = load i32, i32* %130, align 4
  %scevgep118 = getelementptr i32, i32* %54, i64 %indvars.iv
  %scevgep119 = getelementptr i32, i32* %scevgep118, i64 -80
  store i32 %131, i32* %scevgep119, align 4
  %132 = or i32 %131, %.02027
  %133 = add i32 %lsr.iv106, 1
  %134 = sext i32 %133 to i64
  %135 = getelementptr i32, i32* %123, i64 %134
  %136 = load i32, i32* %135, align 4
  %scevgep117 = getelementptr i32, i32* %scevgep118, i64 -64
  store i32 %136, i32* %scevgep117, align 4
  %137 = or i32 %132, %136
  %138 = add i32 %lsr.iv106, 2
  %139 = sext i32 %138 to i64
  %140 = getelementptr i32, i32* %123, i64 %139
  %141 = load i32, i32* %140, align 4
  %scevgep115 = getelementptr i32, i32* %scevgep118, i64 -48
  store i32 %141, i32* %scevgep115, align 4
  %142 = or i32 %137, %141
  %143 = add i32 %37, %lsr.iv106
  %144 = sext i32 %143 to i64
  %145 = getelementptr i32, i32* %123, i64 %144
  %146 = load i32, i32* %145, align 4
  %scevgep113 = getelementptr i32, i32* %scevgep118, i64 -32
  store i32 %146, i32* %scevgep113, align 4
  %147 = or i32 %142, %146
  %148 = add i32 %66, %lsr.iv106
  %149 = add i32 %148, 1
  %150 = sext i32 %149 to i64
  %151 = getelementptr i32, i32* %123, i64 %150
  %152 = load i32, i32* %151, align 4
  %scevgep111 = getelementptr i32, i32* %scevgep118, i64 -16
  store i32 %152, i32* %scevgep111, align 4
  %153 = or i32 %147, %152
  %154 = add i32 %148, 2
  %155 = sext i32 %154 to i64
  %156 = getelementptr i32, i32* %123, i64 %155
  %157 = load i32, i32* %156, align 4
  store i32 %157, i32* %scevgep118, align 4
  %158 = or i32 %153, %157
  %indvars.iv.next = add nuw nsw i64 %indvars.iv, 1
  %lsr.iv.next107 = add i32 %lsr.iv106, 3
  %159 = icmp slt i64 %indvars.iv.next, %89
  br i1 %159, label %for_loop_body1, label %after_for3.loopexit, !llvm.loop !8

after_for3.loopexit:                              ; preds = %for_loop_body1
  br label %after_for3

after_for3:                                       ; preds = %after_for3.loopexit, %middle.block56, %for_loop_body
  %.020.lcssa = phi i32 [ 0, %for_loop_body ], [ %122, %middle.block56 ], [ %158, %after_for3.loopexit ]
  call void @llvm.memset.p0i8.i64(i8* noundef nonnull align 4 dereferenceable(128) %42, i8 0, i64 128, i1 false)
  call void @llvm.memset.p0i8.i64(i8* noundef nonnull align 4 dereferenceable(64) %4, i8 0, i64 64, i1 false)
  %160 = icmp eq i32 %.020.lcssa, 0
  call void @llvm.memset.p0i8.i64(i8* noundef nonnull align 4 dereferenceable(64) %6, i8 0, i64 64, i1 false)
  br i1 %160, label %for_loop_body5.preheader, label %vector.ph

vector.ph:                                        ; preds = %after_for3
  %load_initial = load <16 x i32>, <16 x i32>* %2, align 4
  %wide.load = load <16 x i32>, <16 x i32>* %43, align 4
  %161 = and <16 x i32> %wide.load, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %162 = lshr <16 x i32> %wide.load, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %163 = and <16 x i32> %162, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %164 = lshr <16 x i32> %wide.load, <i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16>
  %165 = and <16 x i32> %164, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %166 = mul nuw nsw <16 x i32> %161, <i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829>
  %167 = mul nuw nsw <16 x i32> %163, <i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039>
  %168 = mul nuw nsw <16 x i32> %165, <i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416>
  %169 = add nuw nsw <16 x i32> %166, <i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768>
  %170 = add nuw nsw <16 x i32> %169, %167
  %171 = add nuw nsw <16 x i32> %170, %168
  %172 = lshr <16 x i32> %171, <i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16>
  %173 = add nuw nsw <16 x i32> %172, <i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16>
  %174 = or <16 x i32> %173, %load_initial
  %wide.load48 = load <16 x i32>, <16 x i32>* %45, align 4
  %175 = lshr <16 x i32> %wide.load, <i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24>
  %176 = and <16 x i32> %wide.load48, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %177 = lshr <16 x i32> %wide.load48, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %178 = and <16 x i32> %177, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %179 = add nuw nsw <16 x i32> %161, %175
  %180 = add nuw nsw <16 x i32> %176, %163
  %181 = add nuw nsw <16 x i32> %178, %165
  %182 = mul nuw nsw <16 x i32> %175, <i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829>
  %183 = mul nuw nsw <16 x i32> %176, <i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039>
  %184 = mul nuw nsw <16 x i32> %178, <i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416>
  %185 = add nuw nsw <16 x i32> %182, <i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768>
  %186 = add nuw nsw <16 x i32> %185, %183
  %187 = add nuw nsw <16 x i32> %186, %184
  %188 = lshr <16 x i32> %187, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %189 = and <16 x i32> %188, <i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960>
  %190 = add nuw nsw <16 x i32> %189, <i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096>
  %191 = or <16 x i32> %190, %174
  %wide.load49 = load <16 x i32>, <16 x i32>* %47, align 4
  %192 = lshr <16 x i32> %wide.load48, <i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16>
  %193 = and <16 x i32> %192, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %194 = lshr <16 x i32> %wide.load48, <i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24>
  %195 = and <16 x i32> %wide.load49, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %196 = mul nuw nsw <16 x i32> %193, <i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829>
  %197 = mul nuw nsw <16 x i32> %194, <i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039>
  %198 = mul nuw nsw <16 x i32> %195, <i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416>
  %199 = add nuw nsw <16 x i32> %197, <i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768>
  %200 = add nuw nsw <16 x i32> %199, %196
  %201 = add nuw nsw <16 x i32> %200, %198
  %202 = and <16 x i32> %201, <i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192>
  %203 = add nuw nsw <16 x i32> %202, <i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576>
  %204 = or <16 x i32> %191, %203
  %205 = lshr <16 x i32> %wide.load49, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %206 = and <16 x i32> %205, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %207 = lshr <16 x i32> %wide.load49, <i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16>
  %208 = and <16 x i32> %207, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %209 = lshr <16 x i32> %wide.load49, <i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24>
  %210 = add nuw nsw <16 x i32> %206, %193
  %211 = add nuw nsw <16 x i32> %208, %194
  %212 = add nuw nsw <16 x i32> %195, %209
  %213 = mul nuw nsw <16 x i32> %206, <i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829>
  %214 = mul nuw nsw <16 x i32> %208, <i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039>
  %215 = mul nuw nsw <16 x i32> %209, <i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416>
  %216 = add nuw nsw <16 x i32> %214, %215
  %217 = add nuw nsw <16 x i32> %216, %213
  %218 = shl nuw <16 x i32> %217, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %219 = add nuw <16 x i32> %218, <i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064>
  %220 = and <16 x i32> %219, <i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216>
  %221 = or <16 x i32> %204, %220
  store <16 x i32> %221, <16 x i32>* %2, align 4
  %wide.load50 = load <16 x i32>, <16 x i32>* %49, align 4
  %222 = and <16 x i32> %wide.load50, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %223 = lshr <16 x i32> %wide.load50, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %224 = and <16 x i32> %223, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %225 = lshr <16 x i32> %wide.load50, <i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16>
  %226 = and <16 x i32> %225, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %227 = add nuw nsw <16 x i32> %179, %222
  %228 = add nuw nsw <16 x i32> %180, %224
  %229 = add nuw nsw <16 x i32> %181, %226
  %230 = mul nuw nsw <16 x i32> %222, <i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829>
  %231 = mul nuw nsw <16 x i32> %224, <i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039>
  %232 = mul nuw nsw <16 x i32> %226, <i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416>
  %233 = add nuw nsw <16 x i32> %230, <i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768>
  %234 = add nuw nsw <16 x i32> %233, %231
  %235 = add nuw nsw <16 x i32> %234, %232
  %236 = lshr <16 x i32> %235, <i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16>
  %237 = add nuw nsw <16 x i32> %236, <i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16>
  %wide.load51 = load <16 x i32>, <16 x i32>* %51, align 4
  %238 = or <16 x i32> %237, %wide.load51
  %wide.load52 = load <16 x i32>, <16 x i32>* %53, align 4
  %239 = lshr <16 x i32> %wide.load50, <i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24>
  %240 = and <16 x i32> %wide.load52, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %241 = lshr <16 x i32> %wide.load52, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %242 = and <16 x i32> %241, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %243 = add nuw nsw <16 x i32> %227, %239
  %244 = add nuw nsw <16 x i32> %228, %240
  %245 = add nuw nsw <16 x i32> %229, %242
  %246 = mul nuw nsw <16 x i32> %239, <i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829>
  %247 = mul nuw nsw <16 x i32> %240, <i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039>
  %248 = mul nuw nsw <16 x i32> %242, <i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416>
  %249 = add nuw nsw <16 x i32> %246, <i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768>
  %250 = add nuw nsw <16 x i32> %249, %247
  %251 = add nuw nsw <16 x i32> %250, %248
  %252 = lshr <16 x i32> %251, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %253 = and <16 x i32> %252, <i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960, i32 16776960>
  %254 = add nuw nsw <16 x i32> %253, <i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096, i32 4096>
  %255 = or <16 x i32> %238, %254
  %wide.load53 = load <16 x i32>, <16 x i32>* %55, align 4
  %256 = lshr <16 x i32> %wide.load52, <i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16>
  %257 = and <16 x i32> %256, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %258 = lshr <16 x i32> %wide.load52, <i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24>
  %259 = and <16 x i32> %wide.load53, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %260 = add nuw nsw <16 x i32> %210, %257
  %261 = add nuw nsw <16 x i32> %211, %258
  %262 = add nuw nsw <16 x i32> %212, %259
  %263 = mul nuw nsw <16 x i32> %257, <i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829>
  %264 = mul nuw nsw <16 x i32> %258, <i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039>
  %265 = mul nuw nsw <16 x i32> %259, <i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416>
  %266 = add nuw nsw <16 x i32> %264, <i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768>
  %267 = add nuw nsw <16 x i32> %266, %263
  %268 = add nuw nsw <16 x i32> %267, %265
  %269 = and <16 x i32> %268, <i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192, i32 134152192>
  %270 = add nuw nsw <16 x i32> %269, <i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576, i32 1048576>
  %271 = or <16 x i32> %255, %270
  %272 = lshr <16 x i32> %wide.load53, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %273 = and <16 x i32> %272, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %274 = lshr <16 x i32> %wide.load53, <i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16, i32 16>
  %275 = and <16 x i32> %274, <i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255, i32 255>
  %276 = lshr <16 x i32> %wide.load53, <i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24, i32 24>
  %277 = add nuw nsw <16 x i32> %260, %273
  %278 = add nuw nsw <16 x i32> %261, %275
  %279 = add nuw nsw <16 x i32> %262, %276
  %280 = mul nuw nsw <16 x i32> %273, <i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829, i32 16829>
  %281 = mul nuw nsw <16 x i32> %275, <i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039, i32 33039>
  %282 = mul nuw nsw <16 x i32> %276, <i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416, i32 6416>
  %283 = add nuw nsw <16 x i32> %281, %282
  %284 = add nuw nsw <16 x i32> %283, %280
  %285 = shl nuw <16 x i32> %284, <i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8, i32 8>
  %286 = add nuw <16 x i32> %285, <i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064, i32 276824064>
  %287 = and <16 x i32> %286, <i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216, i32 -16777216>
  %288 = or <16 x i32> %271, %287
  store <16 x i32> %288, <16 x i32>* %51, align 4
  %289 = mul nsw <16 x i32> %243, <i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714>
  %290 = mul nsw <16 x i32> %244, <i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070>
  %291 = mul nuw nsw <16 x i32> %245, <i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784>
  %292 = add nsw <16 x i32> %289, <i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072>
  %293 = add nsw <16 x i32> %292, %290
  %294 = add nsw <16 x i32> %293, %291
  %295 = ashr <16 x i32> %294, <i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18>
  %296 = add nsw <16 x i32> %295, <i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128>
  %297 = mul nuw nsw <16 x i32> %243, <i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784>
  %298 = mul nsw <16 x i32> %244, <i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103>
  %299 = mul nsw <16 x i32> %245, <i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681>
  %300 = add nuw nsw <16 x i32> %297, <i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072>
  %301 = add nsw <16 x i32> %300, %298
  %302 = add nsw <16 x i32> %301, %299
  %303 = ashr <16 x i32> %302, <i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18, i32 18>
  %304 = add nsw <16 x i32> %303, <i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128, i32 128>
  %wide.load54 = load <16 x i32>, <16 x i32>* %3, align 4
  %305 = or <16 x i32> %296, %wide.load54
  %wide.load55 = load <16 x i32>, <16 x i32>* %5, align 4
  %306 = or <16 x i32> %304, %wide.load55
  %307 = mul nsw <16 x i32> %277, <i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714, i32 -9714>
  %308 = mul nsw <16 x i32> %278, <i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070, i32 -19070>
  %309 = mul nuw nsw <16 x i32> %279, <i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784>
  %310 = add nsw <16 x i32> %308, <i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072>
  %311 = add nsw <16 x i32> %310, %307
  %312 = add nsw <16 x i32> %311, %309
  %313 = mul nuw nsw <16 x i32> %277, <i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784, i32 28784>
  %314 = mul nsw <16 x i32> %278, <i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103, i32 -24103>
  %315 = mul nsw <16 x i32> %279, <i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681, i32 -4681>
  %316 = add nsw <16 x i32> %314, <i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072, i32 131072>
  %317 = add nsw <16 x i32> %316, %313
  %318 = add nsw <16 x i32> %317, %315
  %319 = ashr <16 x i32> %312, <i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10>
  %320 = add nsw <16 x i32> %319, <i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768>
  %321 = and <16 x i32> %320, <i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256>
  %322 = or <16 x i32> %305, %321
  store <16 x i32> %322, <16 x i32>* %3, align 4
  %323 = ashr <16 x i32> %318, <i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10, i32 10>
  %324 = add nsw <16 x i32> %323, <i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768, i32 32768>
  %325 = and <16 x i32> %324, <i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256, i32 -256>
  %326 = or <16 x i32> %306, %325
  store <16 x i32> %326, <16 x i32>* %5, align 4
  br label %after_if

for_loop_body5.preheader:                         ; preds = %after_for3
  call void @llvm.memset.p0i8.i64(i8* noundef nonnull align 4 dereferenceable(128) %42, i8 16, i64 128, i1 false)
  store <8 x i32> <i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896>, <8 x i32>* %56, align 4
  store <8 x i32> <i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896>, <8 x i32>* %57, align 4
  store <8 x i32> <i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896>, <8 x i32>* %58, align 4
  store <8 x i32> <i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896, i32 32896>, <8 x i32>* %59, align 4
  br label %after_if

after_if:                                         ; preds = %vector.ph, %for_loop_body5.preheader
  %327 = shl i32 %76, 1
  %328 = or i32 %327, 1
  %329 = mul i32 %328, %16
  br i1 %87, label %for_loop_body13.lr.ph, label %after_for15

for_loop_body13.lr.ph:                            ; preds = %after_if
  %330 = getelementptr { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }, { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }* %86, i64 0, i32 1, i32 1
  %331 = getelementptr { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }, { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }* %86, i64 0, i32 2, i32 1
  %332 = getelementptr { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }, { { { i32 }, i32* }, { { i32 }, i32* }, { { i32 }, i16* }, { { i32 }, i16* }, i32 }* %86, i64 0, i32 3, i32 1
  %333 = add i32 %lsr.iv127, %329
  %334 = mul i32 %60, %76
  %335 = sub i32 %333, %334
  %336 = zext i32 %335 to i64
  %337 = mul i32 %68, %76
  %338 = add i32 %lsr.iv127, %337
  %339 = zext i32 %338 to i64
  %340 = mul i32 %69, %76
  %341 = add i32 %lsr.iv127, %340
  %342 = zext i32 %341 to i64
  %343 = add i32 %lsr.iv, %334
  %smin132 = call i32 @llvm.smin.i32(i32 %343, i32 16)
  %344 = sext i32 %smin132 to i64
  %smax133 = call i64 @llvm.smax.i64(i64 %344, i64 1)
  br label %for_loop_body13

for_loop_body13:                                  ; preds = %for_loop_body13.lr.ph, %for_loop_body13
  %indvars.iv43 = phi i64 [ 0, %for_loop_body13.lr.ph ], [ %indvars.iv.next44, %for_loop_body13 ]
  %345 = add nuw nsw i64 %342, %indvars.iv43
  %scevgep125 = getelementptr i32, i32* %50, i64 %indvars.iv43
  %scevgep126 = getelementptr i32, i32* %scevgep125, i64 -16
  %346 = load i32, i32* %scevgep126, align 4
  %347 = load i32, i32* %scevgep125, align 4
  %348 = add nuw nsw i64 %339, %indvars.iv43
  %349 = load i32*, i32** %330, align 8
  %tmp129 = trunc i64 %348 to i32
  %350 = sext i32 %tmp129 to i64
  %351 = getelementptr i32, i32* %349, i64 %350
  store i32 %346, i32* %351, align 4
  %352 = add nuw nsw i64 %336, %indvars.iv43
  %353 = load i32*, i32** %330, align 8
  %tmp = trunc i64 %352 to i32
  %354 = sext i32 %tmp to i64
  %355 = getelementptr i32, i32* %353, i64 %354
  store i32 %347, i32* %355, align 4
  %356 = shl nuw nsw i64 %indvars.iv43, 2
  %uglygep121 = getelementptr i8, i8* %4, i64 %356
  %uglygep121122 = bitcast i8* %uglygep121 to i32*
  %357 = load i32, i32* %uglygep121122, align 4
  %358 = trunc i32 %357 to i16
  %uglygep = getelementptr i8, i8* %6, i64 %356
  %uglygep120 = bitcast i8* %uglygep to i32*
  %359 = load i32, i32* %uglygep120, align 4
  %360 = trunc i32 %359 to i16
  %361 = load i16*, i16** %331, align 8
  %tmp130 = trunc i64 %345 to i32
  %362 = sext i32 %tmp130 to i64
  %363 = getelementptr i16, i16* %361, i64 %362
  store i16 %358, i16* %363, align 2
  %364 = load i16*, i16** %332, align 8
  %365 = getelementptr i16, i16* %364, i64 %362
  store i16 %360, i16* %365, align 2
  %indvars.iv.next44 = add nuw nsw i64 %indvars.iv43, 1
  %exitcond = icmp ne i64 %indvars.iv.next44, %smax133
  br i1 %exitcond, label %for_loop_body13, label %after_for15.loopexit

after_for15.loopexit:                             ; preds = %for_loop_body13
  br label %after_for15

after_for15:                                      ; preds = %after_for15.loopexit, %after_if
  %366 = add nuw nsw i32 %.02132, 1
  %lsr.iv.next = add i32 %lsr.iv, -16
  %lsr.iv.next105 = add i32 %lsr.iv104, 48
  %lsr.iv.next128 = add i32 %lsr.iv127, 16
  %exitcond46.not = icmp eq i32 %366, %35
  br i1 %exitcond46.not, label %after_for.loopexit, label %for_loop_body
}

; Function Attrs: mustprogress nocallback nofree nosync nounwind readnone speculatable willreturn
declare i32 @llvm.smin.i32(i32, i32) #1

; Function Attrs: argmemonly nocallback nofree nounwind willreturn writeonly
declare void @llvm.memset.p0i8.i64(i8* nocapture writeonly, i8, i64, i1 immarg) #2

; Function Attrs: nocallback nofree nosync nounwind readnone speculatable willreturn
declare i64 @llvm.smax.i64(i64, i64) #3

; Function Attrs: nocallback nofree nosync nounwind readonly willreturn
declare <8 x i32> @llvm.masked.gather.v8i32.v8p0i32(<8 x i32*>, i32 immarg, <8 x i1>, <8 x i32>) #4

; Function Attrs: nocallback nofree nosync nounwind readnone willreturn
declare i32 @llvm.vector.reduce.or.v8i32(<8 x i32>) #5

attributes #0 = { nofree nosync nounwind }
attributes #1 = { mustprogress nocallback nofree nosync nounwind readnone speculatable willreturn }
attributes #2 = { argmemonly nocallback nofree nounwind willreturn writeonly }
attributes #3 = { nocallback nofree nosync nounwind readnone speculatable willreturn }
attributes #4 = { nocallback nofree nosync nounwind readonly willreturn }
attributes #5 = { nocallback nofree nosync nounwind readnone willreturn }

!llvm.ident = !{!0}
!llvm.module.flags = !{!1, !2, !3, !4, !5}

!0 = !{!"Ubuntu clang version 14.0.6"}
!1 = !{i32 1, !"wchar_size", i32 4}
!2 = !{i32 7, !"PIC Level", i32 2}
!3 = !{i32 7, !"PIE Level", i32 2}
!4 = !{i32 7, !"uwtable", i32 1}
!5 = !{i32 7, !"frame-pointer", i32 2}
!6 = distinct !{!6, !7}
!7 = !{!"llvm.loop.isvectorized", i32 1}
!8 = distinct !{!8, !9, !7}
!9 = !{!"llvm.loop.unroll.runtime.disable"}
